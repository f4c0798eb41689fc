#include "pipeline/run/camera_pipeline.h"

#include <chrono>

#include "core/error.h"
#include "core/log.h"
#include "pipeline/describe/sprite_description.h"
#include "pipeline/key/chroma_keyer.h"
#include "pipeline/key/clean_plate_keyer.h"

namespace ss {
namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

std::unique_ptr<Keyer> MakeKeyer(const std::string& method) {
  if (method == "chroma") return std::make_unique<ChromaKeyer>();
  if (method == "clean_plate") return std::make_unique<CleanPlateKeyer>();
  throw InputError("keying.method", "expected chroma or clean_plate, got \"" + method + "\"");
}

}  // namespace

CameraPipelineOptions PipelineOptionsFromConfig(const StationConfig& config) {
  const PipelineConfig& p = config.pipeline;
  CameraPipelineOptions o;
  o.keying_method = config.keying.method;
  o.extract.min_area = p.min_area_px;
  o.usability.border_margin_px = p.border_margin_px;
  o.usability.floor_margin_px = p.floor_margin_px;
  o.usability.wall_margin_m = p.wall_margin_m;
  o.usability.wall_height_m = config.enclosure.wall_height_m;
  o.still_speed_m_per_s = p.still_speed_m_per_s;
  o.max_still_s = p.max_still_s;
  o.rectify.px_per_m = p.px_per_m;
  o.batch.min_clip_frames = p.min_clip_frames;
  return o;
}

CameraPipeline::CameraPipeline(std::string name, int64_t camera_id, CameraModel model, GroundPolygon floor,
                               CameraPipelineOptions options)
    : name_(std::move(name)),
      camera_id_(camera_id),
      model_(model.valid() ? std::move(model)
                           : throw InputError(name_, "the camera has no model: calibrate it first "
                                                     "(spritestation calibrate)")),
      options_(options),
      keyer_(MakeKeyer(options.keying_method)),
      floor_mask_(model_, floor, options.usability),
      extractor_(options.extract),
      tracker_(options.track),
      stillness_(options.still_speed_m_per_s, options.max_still_s),
      rectifier_(options.rectify),
      batcher_(camera_id, options.batch) {}

CameraPipeline::~CameraPipeline() = default;
CameraPipeline::CameraPipeline(CameraPipeline&&) noexcept = default;

void CameraPipeline::Train(const std::vector<cv::Mat>& empty_bgr) {
  for (const cv::Mat& m : empty_bgr) {
    if (m.cols != model_.width() || m.rows != model_.height()) {
      throw InputError(name_, "training frame is " + std::to_string(m.cols) + "x" + std::to_string(m.rows) +
                                  " but the camera model is " + std::to_string(model_.width()) + "x" +
                                  std::to_string(model_.height()));
    }
  }
  keyer_->Train(empty_bgr);
  stats_.training_frames += empty_bgr.size();
  stats_.frames += empty_bgr.size();
}

bool CameraPipeline::trained() const { return keyer_->trained(); }

void CameraPipeline::Process(const Frame& frame, std::vector<ClipBatch>* out) {
  if (!keyer_->trained()) throw WorkError(name_, "the keyer has not learnt the empty enclosure yet");
  if (frame.width != model_.width() || frame.height != model_.height()) {
    throw InputError(name_ + " frame " + std::to_string(frame.sequence),
                     "frame is " + std::to_string(frame.width) + "x" + std::to_string(frame.height) +
                         " but the camera (and its model) is " + std::to_string(model_.width()) + "x" +
                         std::to_string(model_.height()));
  }
  ++stats_.frames;
  // A gap in the sequence numbers is a lost frame: clips cannot run across it.
  if (last_sequence_ && frame.sequence != *last_sequence_ + 1) {
    ++stats_.sequence_gaps;
    for (const int64_t clip : cutter_.CloseAll()) batcher_.Close(clip, out);
  }
  last_sequence_ = frame.sequence;

  const auto key_start = Clock::now();
  ToBgr(frame, bgr_);
  keyer_->Key(bgr_, matte_);
  const std::vector<Candidate>& candidates = extractor_.Extract(matte_);
  stats_.seconds_key += SecondsSince(key_start);
  const auto rest_start = Clock::now();
  stats_.discards[static_cast<size_t>(Discard::kTooSmall)] += extractor_.dropped_last();
  stats_.candidates += candidates.size();

  // Contact points: the ray through each candidate's lowest point meets the floor.
  std::vector<const Candidate*> grounded;
  std::vector<Eigen::Vector2d> points;
  std::vector<TrackInput> inputs;
  for (const Candidate& c : candidates) {
    const auto hit = IntersectGround(model_.RayInGround(Eigen::Vector2d(c.lowest_point.x, c.lowest_point.y)));
    if (!hit) {
      ++stats_.discards[static_cast<size_t>(Discard::kNoGroundHit)];
      continue;
    }
    grounded.push_back(&c);
    points.emplace_back(hit->x(), hit->y());
    inputs.push_back({points.back(), c.area});
  }
  const std::vector<int> subjects = tracker_.Update(frame.timestamp_ns, inputs);

  // Filter and rectify.
  std::vector<bool> usable(subjects.size(), false);
  std::vector<std::optional<Billboard>> billboards(subjects.size());
  for (size_t k = 0; k < subjects.size(); ++k) {
    const Candidate& c = *grounded[k];
    Discard reason = c.touches_border ? Discard::kTouchesBorder : floor_mask_.Check(c.alpha, c.bbox.tl(), points[k]);
    const bool still = stillness_.IsStill(subjects[k], frame.timestamp_ns, points[k]);
    if (reason == Discard::kNone && still) reason = Discard::kStill;
    if (reason == Discard::kNone) {
      const SpriteView view{&c.colour, &c.alpha, &c.shadow, c.bbox.tl(),
                            Eigen::Vector2d(c.lowest_point.x, c.lowest_point.y)};
      billboards[k] = rectifier_.Rectify(model_, view);
      if (!billboards[k]) reason = Discard::kNoGroundHit;
    }
    usable[k] = reason == Discard::kNone;
    if (usable[k]) {
      ++usable_total_;
    } else {
      ++stats_.discards[static_cast<size_t>(reason)];
    }
  }

  // Clips: runs of consecutive usable frames per subject.
  const std::vector<ClipCutter::Event> events = cutter_.Update(subjects, usable);
  for (const ClipCutter::Event& e : events) {
    if (e.closes) batcher_.Close(e.closed_clip, out);
  }
  const size_t first_input_event = events.size() - subjects.size();
  for (size_t k = 0; k < subjects.size(); ++k) {
    const ClipCutter::Event& e = events[first_input_event + k];
    if (e.clip < 0) continue;
    MadeSprite s;
    s.frame = static_cast<int64_t>(frame.sequence);
    s.timestamp_ns = frame.timestamp_ns;
    s.bbox_in_image = grounded[k]->bbox;
    s.billboard = std::move(*billboards[k]);
    s.description = DescribeBillboard(s.billboard.bgra);
    batcher_.Add(e.clip, e.subject, std::move(s), out);
  }
  UpdateClipStats();
  stats_.seconds_rest += SecondsSince(rest_start);
}

void CameraPipeline::Finish(std::vector<ClipBatch>* out) {
  for (const int64_t clip : cutter_.CloseAll()) batcher_.Close(clip, out);
  batcher_.CloseAll(out);
  UpdateClipStats();
}

void CameraPipeline::UpdateClipStats() {
  const uint64_t short_sprites = batcher_.short_clip_sprites();
  stats_.discards[static_cast<size_t>(Discard::kShortClip)] = short_sprites;
  stats_.discards[static_cast<size_t>(Discard::kNone)] = usable_total_ - short_sprites;
  stats_.stored_sprites = batcher_.stored_originals();
  stats_.clips = batcher_.clips_completed();
}

}  // namespace ss
