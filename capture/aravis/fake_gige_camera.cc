#include "capture/aravis/fake_gige_camera.h"

#include <arv.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <mutex>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "capture/aravis/gobject_ptr.h"
#include "capture/aravis/pixel_formats.h"
#include "capture/replay/replay_source.h"
#include "core/error.h"
#include "core/log.h"
#include "core/option_checks.h"

namespace ss {
namespace {

bool GigECarries(PixelFormat f) {
  switch (f) {
    case PixelFormat::kMono8:
    case PixelFormat::kBayerRG8:
    case PixelFormat::kBayerGR8:
    case PixelFormat::kBayerGB8:
    case PixelFormat::kBayerBG8:
    case PixelFormat::kRGB8:
      return true;
    default:
      return false;  // the fake camera's GenICam description offers only these (and Mono16)
  }
}

// Channel (B=0, G=1, R=2) sampled at (row parity, column parity) for each Bayer layout.
void BayerLayout(PixelFormat f, int layout[2][2]) {
  const char* p = "RGGB";
  if (f == PixelFormat::kBayerGR8) p = "GRBG";
  if (f == PixelFormat::kBayerGB8) p = "GBRG";
  if (f == PixelFormat::kBayerBG8) p = "BGGR";
  for (int i = 0; i < 4; ++i) layout[i / 2][i % 2] = p[i] == 'B' ? 0 : (p[i] == 'G' ? 1 : 2);
}

}  // namespace

void ConvertForGigE(const Frame& frame, PixelFormat target, std::vector<uint8_t>& out) {
  const size_t bytes = FrameBytes(target, frame.width, frame.height);
  if (bytes == 0)
    throw InputError("pixel_format",
                     PixelFormatName(target) + " cannot be streamed over GigE Vision");
  out.resize(bytes);
  if (frame.format == target) {
    std::memcpy(out.data(), frame.data, std::min(bytes, frame.size));
    return;
  }
  const cv::Mat bgr = ToBgr(frame);
  switch (target) {
    case PixelFormat::kMono8:
      cv::cvtColor(bgr, cv::Mat(frame.height, frame.width, CV_8UC1, out.data()),
                   cv::COLOR_BGR2GRAY);
      return;
    case PixelFormat::kRGB8:
      cv::cvtColor(bgr, cv::Mat(frame.height, frame.width, CV_8UC3, out.data()), cv::COLOR_BGR2RGB);
      return;
    case PixelFormat::kBGR8:
      bgr.copyTo(cv::Mat(frame.height, frame.width, CV_8UC3, out.data()));
      return;
    case PixelFormat::kBayerRG8:
    case PixelFormat::kBayerGR8:
    case PixelFormat::kBayerGB8:
    case PixelFormat::kBayerBG8: {
      int layout[2][2];
      BayerLayout(target, layout);
      for (int y = 0; y < frame.height; ++y) {
        const uint8_t* row = bgr.ptr<uint8_t>(y);
        uint8_t* dst = out.data() + static_cast<size_t>(y) * static_cast<size_t>(frame.width);
        for (int x = 0; x < frame.width; ++x) dst[x] = row[3 * x + layout[y & 1][x & 1]];
      }
      return;
    }
    default:
      throw InputError("pixel_format",
                       PixelFormatName(target) + " cannot be streamed by the emulated camera");
  }
}

struct FakeGigECamera::Impl {
  FakeGigEOptions options;
  std::unique_ptr<ReplaySource> replay;
  int camera_index = 0;
  PixelFormat session_format = PixelFormat::kMono8;
  PixelFormat format = PixelFormat::kMono8;
  int width = 0;
  int height = 0;
  double fps = 0.0;
  std::string device_id;
  GObjectPtr<ArvGvFakeCamera> gv;

  // Touched only by the fake camera's thread, inside the fill callback:
  std::optional<Frame> last;  // the frame served last (repeated once a finite replay ends)
  std::vector<uint8_t> converted;
  std::atomic<uint64_t> served{0};
  std::atomic<bool> finished{false};
  bool warned_geometry = false;

  // Fills one outgoing buffer: the next session frame for this camera, in the
  // format and region the client asked for, with the frame's device timestamp.
  void Fill(ArvBuffer* buffer, ArvPixelFormat code) {
    if (!finished.load()) {
      bool got = false;
      while (auto frame = replay->Next()) {
        if (frame->camera != camera_index) continue;  // another camera of the session
        last = std::move(frame);
        got = true;
        break;
      }
      if (!got) {
        finished.store(true);
        Log("capture.fakecam")
            ->info("{}: the session has been served; repeating its last frame", device_id);
      }
    }
    const int w = arv_buffer_get_image_width(buffer);
    const int h = arv_buffer_get_image_height(buffer);
    const auto target = FromGenicamPixelFormat(code);
    size_t capacity = 0;
    // The fake camera allocates the buffer for the payload of the current registers.
    auto* data =
        const_cast<uint8_t*>(static_cast<const uint8_t*>(arv_buffer_get_data(buffer, &capacity)));
    const size_t bytes = target ? FrameBytes(*target, w, h) : 0;
    if (data == nullptr || bytes == 0) return;
    std::memset(data, 0, bytes);
    if (!last) return;
    ConvertForGigE(*last, *target, converted);
    // Copy the overlap of the session frame and the requested region, row by row.
    const size_t bpp = FrameBytes(*target, 1, 1);
    const size_t src_stride = static_cast<size_t>(last->width) * bpp;
    const size_t dst_stride = static_cast<size_t>(w) * bpp;
    const size_t row_bytes = std::min(src_stride, dst_stride);
    const int rows = std::min(h, last->height);
    for (int y = 0; y < rows; ++y) {
      std::memcpy(data + static_cast<size_t>(y) * dst_stride,
                  converted.data() + static_cast<size_t>(y) * src_stride, row_bytes);
    }
    if ((w != last->width || h != last->height) && !warned_geometry) {
      warned_geometry = true;
      Log("capture.fakecam")
          ->warn("{}: client asked for {}x{}, the session is {}x{}; frames are cropped/padded",
                 device_id, w, h, last->width, last->height);
    }
    arv_buffer_set_timestamp(buffer, static_cast<guint64>(last->timestamp_ns));
    served.fetch_add(1);
  }

  static void FillPattern(ArvBuffer* buffer, void* self, guint32 /*exposure_us*/, guint32 /*gain*/,
                          ArvPixelFormat code) {
    auto* impl = static_cast<Impl*>(self);
    try {
      impl->Fill(buffer, code);
    } catch (const std::exception& e) {
      Log("capture.fakecam")->error("{}: {}", impl->device_id, e.what());
    }
  }
};

bool FakeGigEOptions::IsValid(std::string* why) const {
  OptionProblems check(why);
  // The GVCP bootstrap register holds 16 bytes with the terminating NUL.
  check(!serial.empty() && serial.size() < 16, "serial",
        "expected 1 to 15 characters, got '" + serial + "'");
  check(!pixel_format || GigECarries(*pixel_format), "pixel_format",
        (pixel_format ? PixelFormatName(*pixel_format) : std::string()) +
            " is not offered by the emulated camera (mono8, bayer_rg8, bayer_gr8, bayer_gb8, "
            "bayer_bg8, rgb8)");
  check.Within(fps, AtLeast(0), "fps", "0 (the session's) or a positive frame rate");
  check.Within(loops, AtLeast(0), "loops", "0 (forever) or more");
  check.Within(lost_packet_ratio, Between(0, 1), "lost_packet_ratio", "0..1");
  return check.ok();
}

FakeGigECamera::FakeGigECamera(const std::string& session_dir, FakeGigEOptions options)
    : impl_(std::make_unique<Impl>()) {
  Impl& s = *impl_;
  s.options = options;
  if (std::string why; !options.IsValid(&why)) throw InputError("fake camera options", why);
  ReplayOptions replay_options;
  replay_options.loops = options.loops;
  s.replay = std::make_unique<ReplaySource>(session_dir, replay_options);
  const auto& cams = s.replay->cameras();
  s.camera_index = -1;
  for (size_t i = 0; i < cams.size(); ++i) {
    if (options.camera.empty() || cams[i].name == options.camera) {
      s.camera_index = static_cast<int>(i);
      break;
    }
  }
  if (s.camera_index < 0) {
    throw InputError("camera",
                     "session " + session_dir + " has no camera '" + options.camera + "'");
  }
  const SourceCamera& cam = cams[static_cast<size_t>(s.camera_index)];
  s.session_format = cam.format;
  s.format = options.pixel_format ? *options.pixel_format
                                  : (GigECarries(cam.format) ? cam.format : PixelFormat::kRGB8);
  if (!GigECarries(s.format)) {
    throw InputError("pixel_format",
                     PixelFormatName(s.format) +
                         " is not offered by the emulated camera (mono8, bayer_rg8, bayer_gr8, "
                         "bayer_gb8, bayer_bg8, rgb8)");
  }
  if (cam.width > ARV_FAKE_CAMERA_SENSOR_WIDTH || cam.height > ARV_FAKE_CAMERA_SENSOR_HEIGHT) {
    throw InputError(session_dir, "camera '" + cam.name + "' is " + std::to_string(cam.width) +
                                      "x" + std::to_string(cam.height) +
                                      ", larger than the emulated sensor (2048x2048)");
  }
  s.width = cam.width;
  s.height = cam.height;
  s.fps = options.fps > 0 ? options.fps : (cam.fps > 0 ? cam.fps : 30.0);
  s.device_id = "Aravis-Fake-" + options.serial;

  s.gv.reset(arv_gv_fake_camera_new(options.address.c_str(), options.serial.c_str()));
  if (!s.gv || !arv_gv_fake_camera_is_running(s.gv.get())) {
    throw WorkError("address " + options.address,
                    "cannot serve GigE Vision there (no interface with that name or address, or "
                    "UDP port 3956 is "
                    "already taken by another camera)");
  }
  if (options.lost_packet_ratio > 0)
    g_object_set(s.gv.get(), "gvsp-lost-ratio", options.lost_packet_ratio, nullptr);
  ArvFakeCamera* fake = arv_gv_fake_camera_get_fake_camera(s.gv.get());
  arv_fake_camera_write_register(fake, ARV_FAKE_CAMERA_REGISTER_WIDTH,
                                 static_cast<guint32>(s.width));
  arv_fake_camera_write_register(fake, ARV_FAKE_CAMERA_REGISTER_HEIGHT,
                                 static_cast<guint32>(s.height));
  arv_fake_camera_write_register(fake, ARV_FAKE_CAMERA_REGISTER_PIXEL_FORMAT,
                                 *GenicamPixelFormat(s.format));
  arv_fake_camera_write_register(fake, ARV_FAKE_CAMERA_REGISTER_ACQUISITION_FRAME_PERIOD_US,
                                 static_cast<guint32>(std::lround(1e6 / s.fps)));
  arv_fake_camera_set_fill_pattern(fake, &Impl::FillPattern, &s);
  Log("capture.fakecam")
      ->info("{} serving {} camera '{}' ({} {}x{} at {:.2f} frames/s) on {}", s.device_id,
             session_dir, cam.name, PixelFormatName(s.format), s.width, s.height, s.fps,
             options.address);
}

FakeGigECamera::~FakeGigECamera() {
  impl_->replay->Stop();  // unblocks a fill waiting for a decoded frame
  impl_->gv.reset();      // joins the fake camera's thread
}

const std::string& FakeGigECamera::device_id() const { return impl_->device_id; }
PixelFormat FakeGigECamera::pixel_format() const { return impl_->format; }
int FakeGigECamera::width() const { return impl_->width; }
int FakeGigECamera::height() const { return impl_->height; }
double FakeGigECamera::fps() const { return impl_->fps; }
uint64_t FakeGigECamera::frames_served() const { return impl_->served.load(); }
uint32_t FakeGigECamera::exposure_us() const {
  guint32 value = 0;
  arv_fake_camera_read_register(arv_gv_fake_camera_get_fake_camera(impl_->gv.get()),
                                ARV_FAKE_CAMERA_REGISTER_EXPOSURE_TIME_US, &value);
  return value;
}
uint32_t FakeGigECamera::gain() const {
  guint32 value = 0;
  arv_fake_camera_read_register(arv_gv_fake_camera_get_fake_camera(impl_->gv.get()),
                                ARV_FAKE_CAMERA_REGISTER_GAIN_RAW, &value);
  return value;
}
bool FakeGigECamera::finished() const { return impl_->finished.load(); }

}  // namespace ss
