// The console's previews of each camera: the raw and keyed views and the sprites view, each
// encoded once a snapshot for every viewer (PreviewCache, station_impl.h).
#include <algorithm>
#include <mutex>

#include <nlohmann/json.hpp>

#include "core/error_kinds.h"
#include "station/preview.h"
#include "station/station.h"
#include "station/station_impl.h"

namespace ss {

PreviewCache::Entry* Station::Impl::CachedPreview(const std::string& camera, int view, int width,
                                                  std::unique_lock<std::mutex>* lock,
                                                  std::shared_ptr<const PreviewFrame>* frame,
                                                  const CameraRunner** runner) const {
  for (size_t k = 0; k < runners.size(); ++k) {
    if (runners[k]->name() != camera) continue;
    PreviewCache& cache = *preview_caches[k];
    *lock = std::unique_lock(cache.mutex);
    *runner = runners[k].get();
    *frame = runners[k]->preview();
    if (!*frame) return nullptr;
    PreviewCache::Entry& entry = cache.entries[{view, width}];
    if (entry.frame_taken == (*frame)->taken) {
      *frame = nullptr;  // made from this snapshot already
    } else {
      entry.frame_taken = (*frame)->taken;
    }
    return &entry;
  }
  throw NotFoundError("camera", "no camera named \"" + camera + "\"");
}

std::optional<Station::PreviewImage> Station::Preview(const std::string& camera, PreviewView view,
                                                      int max_width) const {
  const int width = std::clamp(max_width, 16, 4096);
  std::unique_lock<std::mutex> lock;
  std::shared_ptr<const PreviewFrame> frame;
  const CameraRunner* runner = nullptr;
  PreviewCache::Entry* entry = impl_->CachedPreview(camera, view == PreviewView::kKeyed ? 1 : 0,
                                                    width, &lock, &frame, &runner);
  if (entry == nullptr) return std::nullopt;
  if (frame) {
    entry->image = {EncodeJpeg(RenderPreview(*frame, view, width)), frame->sequence,
                    frame->timestamp_ns, frame->bgr.cols, frame->bgr.rows};
  }
  return entry->image;
}

std::optional<std::string> Station::SpritesView(const std::string& camera, int max_width) const {
  const int width = std::clamp(max_width, 16, 4096);
  std::unique_lock<std::mutex> lock;
  std::shared_ptr<const PreviewFrame> frame;
  const CameraRunner* runner = nullptr;
  PreviewCache::Entry* entry = impl_->CachedPreview(camera, 2, width, &lock, &frame, &runner);
  if (entry == nullptr) return std::nullopt;
  if (frame) {
    const cv::Mat image = RenderPreview(*frame, PreviewView::kRaw, width);
    const double scale = frame->bgr.cols > 0 ? double(image.cols) / frame->bgr.cols : 1.0;
    const bool storing = SessionActive() && runner->model().has_value();
    entry->sprites_json =
        SpritesViewJson(*frame, storing, "data:image/jpeg;base64," + Base64(EncodeJpeg(image)),
                        scale)
            .dump();
  }
  return entry->sprites_json;
}

}  // namespace ss
