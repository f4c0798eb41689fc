#include "pipeline/run/camera_pipeline.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "core/elapsed.h"
#include "core/error.h"
#include "core/log.h"
#include "core/option_checks.h"
#include "pipeline/describe/sprite_description.h"
#include "pipeline/key/chroma_keyer.h"
#include "pipeline/key/keyer_registry.h"
#include "pipeline/run/bank_scale.h"

namespace ss {
namespace {

using Clock = std::chrono::steady_clock;

// The keyer the options pick, its shadow reach made grid cells at the floor's scale.
std::unique_ptr<Keyer> KeyerFor(const CameraPipelineOptions& o, const CameraModel& model,
                                const GroundPolygon& floor) {
  if (!o.keying) return std::make_unique<ChromaKeyer>();
  int shadow_reach_cells = 0;
  if (const double px_per_m = FloorPixelsPerMetre(model, floor);
      o.keying->shadow_reach_m > 0 && px_per_m > 0) {
    const int cells =
        static_cast<int>(std::ceil(o.keying->shadow_reach_m * px_per_m / GridOptions{}.step));
    shadow_reach_cells = std::clamp(cells, 1, 64);
  }
  return MakeKeyer(*o.keying, shadow_reach_cells);
}

// `o`, when its values are in range (else InputError naming the field) and the bank's scale is
// chosen (rectify.px_per_m `auto` resolved).
const CameraPipelineOptions& Checked(const std::string& camera, const CameraPipelineOptions& o) {
  if (!(o.rectify.px_per_m > 0)) {
    throw InputError("pipeline.px_per_m", "camera " + camera +
                                              ": the bank's billboard scale was not chosen "
                                              "(ChooseBankScale resolves auto)");
  }
  if (std::string why; !o.IsValid(&why)) throw InputError("pipeline options", why);
  return o;
}

}  // namespace

bool CameraPipelineOptions::IsValid(std::string* why) const {
  OptionProblems check(why);
  std::string part;
  check.Nested(extract.IsValid(&part), "extract.", part);
  check.Nested(track.IsValid(&part), "track.", part);
  check.Nested(usability.IsValid(&part), "usability.", part);
  check.Nested(noise.IsValid(&part), "noise.", part);
  for (const auto& [v, field] : {std::pair{still_speed_m_per_s, "still_speed_m_per_s"},
                                 std::pair{max_still_s, "max_still_s"}}) {
    check(std::isfinite(v) && v > 0, field,
          "expected a positive number, got " + OptionProblems::Num(v));
  }
  // rectify.px_per_m 0 is `auto`, resolved by the caller before a CameraPipeline is made.
  RectifierOptions scaled = rectify;
  if (scaled.px_per_m == 0) scaled.px_per_m = RectifierOptions{}.px_per_m;
  check.Nested(scaled.IsValid(&part), "rectify.", part);
  check.Nested(batch.IsValid(&part), "batch.", part);
  check.Nested(side_by_side.IsValid(&part), "side_by_side.", part);
  check.Within(workers, AtLeast(0), "workers", "0 (one per core) or more");
  check.Within(queue_frames, AtLeast(1), "queue_frames", "at least 1 frame");
  return check.ok();
}

CameraPipeline::CameraPipeline(std::string name, int64_t camera_id, CameraModel model,
                               const GroundPolygon& floor, const CameraPipelineOptions& options)
    : name_(std::move(name)),
      camera_id_(camera_id),
      model_(model.valid() ? std::move(model)
                           : throw InputError(name_,
                                              "the camera has no model: calibrate it first "
                                              "(spritestation calibrate)")),
      options_(Checked(name_, options)),
      keyer_(KeyerFor(options, model_, floor)),
      floor_mask_(model_, floor, options.usability),
      extractor_(options.extract),
      tracker_(options.track),
      side_by_side_(options.side_by_side),
      stillness_(options.still_speed_m_per_s, options.max_still_s),
      noise_(options.noise),
      rectifier_(options.rectify),
      floor_rectifier_(options.rectify),
      batcher_(camera_id, options.batch),
      log_(Log("pipeline.run")) {
  // A camera that sees all of its floor from too far above keeps nothing: say so once, up front.
  if (floor_mask_.FilmsFromAbove()) {
    log_->info(
        "{}: films its floor from above (a median view of {:.0f} degrees, steeper than "
        "pipeline.floor_view_angle_deg {}): its subjects are stored as floor sprites",
        name_, floor_mask_.median_view_deg(), options_.usability.floor_view_angle_deg);
  }
  if (const std::string steep = floor_mask_.SteepViewText(); !steep.empty()) {
    log_->warn(
        "{}: {}: every sprite will be refused as view_too_steep (an upright billboard seen from "
        "above is a sliver; docs/pipeline.md)",
        name_, steep);
  }
}

CameraPipeline::~CameraPipeline() = default;
CameraPipeline::CameraPipeline(CameraPipeline&&) noexcept = default;

void CameraPipeline::Train(const std::vector<cv::Mat>& empty_bgr) {
  for (const cv::Mat& m : empty_bgr) {
    if (m.cols != model_.width() || m.rows != model_.height()) {
      throw InputError(name_, "training frame is " + std::to_string(m.cols) + "x" +
                                  std::to_string(m.rows) + " but the camera model is " +
                                  std::to_string(model_.width()) + "x" +
                                  std::to_string(model_.height()));
    }
  }
  keyer_->Train(empty_bgr);
  // What is not green in the empty enclosure is not floor either: a wall's outside hiding the
  // floor behind it, the room (whatever wall height the config says).
  if (const cv::Mat keyable = keyer_->KeyableMask(); !keyable.empty())
    floor_mask_.Restrict(keyable);
  stats_.training_frames += empty_bgr.size();
  stats_.frames += empty_bgr.size();
}

bool CameraPipeline::trained() const { return keyer_->trained(); }

void CameraPipeline::Process(const Frame& frame, std::vector<ClipBatch>* out) {
  if (!keyer_->trained())
    throw WorkError(name_, "the keyer has not learnt the empty enclosure yet");
  if (frame.width != model_.width() || frame.height != model_.height()) {
    throw InputError(name_ + " frame " + std::to_string(frame.sequence),
                     "frame is " + std::to_string(frame.width) + "x" +
                         std::to_string(frame.height) + " but the camera (and its model) is " +
                         std::to_string(model_.width()) + "x" + std::to_string(model_.height()));
  }
  ++stats_.frames;
  // A gap in the sequence numbers is a lost frame: clips cannot run across it.
  if (last_sequence_ && frame.sequence != *last_sequence_ + 1) {
    ++stats_.sequence_gaps;
    for (const int64_t clip : cutter_.CloseAll()) batcher_.Close(clip, out);
    merges_.Reset();
  }
  last_sequence_ = frame.sequence;

  const auto key_start = Clock::now();
  try {
    // RGB8 and BGR8 frames are keyed in place; other formats go through bgr_scratch_.
    keyer_->Key(frame, bgr_scratch_, matte_);
  } catch (const InputError& e) {  // a corrupt frame: say which camera's
    throw InputError(name_ + " frame " + std::to_string(frame.sequence), e.what());
  }
  const std::vector<Candidate>& candidates = extractor_.Extract(matte_);
  stats_.seconds_key += SecondsSince(key_start);
  const auto rest_start = Clock::now();
  stats_.discards[static_cast<size_t>(Discard::kTooSmall)] += extractor_.dropped_last();
  stats_.candidates += candidates.size();

  // Contact points: the ray through each candidate's contact point meets the floor (from above:
  // the ray through its centre meets its body plane, FloorRectifier::Place).
  std::vector<const Candidate*> grounded;
  std::vector<Eigen::Vector2d> points;
  std::vector<TrackInput> inputs;
  verdicts_.clear();
  const bool from_above = floor_mask_.FilmsFromAbove();
  for (const Candidate& c : candidates) {
    std::optional<Eigen::Vector2d> hit;
    if (from_above) {
      hit = floor_rectifier_.Place(model_, c.alpha, c.bbox.tl());
    } else if (const auto ground = IntersectGround(
                   model_.RayInGround(Eigen::Vector2d(c.contact_point.x, c.contact_point.y)))) {
      hit = ground->head<2>();
    }
    if (!hit) {
      ++stats_.discards[static_cast<size_t>(Discard::kNoGroundHit)];
      verdicts_.push_back({&c, -1, std::nullopt, Discard::kNoGroundHit});
      continue;
    }
    grounded.push_back(&c);
    points.emplace_back(hit->x(), hit->y());
    inputs.push_back({points.back(), c.area});
  }
  const std::vector<int> subjects = tracker_.Update(frame.timestamp_ns, inputs);
  // Two or more subjects in one blob (MergeDetector's rule, docs/pipeline.md "merged"): their
  // sprites are stored tagged `merged`. A pair side by side that the tracks never saw apart is
  // found below, by its looks.
  std::vector<MergeDetector::Blob> blobs(subjects.size());
  for (size_t k = 0; k < subjects.size(); ++k) {
    blobs[k] = {subjects[k], grounded[k]->bbox, grounded[k]->area};
  }
  std::vector<bool> merged = merges_.Update(blobs);
  std::vector<MatteLook> looks(subjects.size());  // of the usable sprites' billboards
  std::vector<size_t> verdict_of(subjects.size());

  // Filter and rectify.
  noise_.NextFrame();
  std::vector<bool> usable(subjects.size(), false);
  std::vector<std::optional<Billboard>> billboards(subjects.size());
  for (size_t k = 0; k < subjects.size(); ++k) {
    const Candidate& c = *grounded[k];
    Discard reason = c.touches_border ? Discard::kTouchesBorder
                                      : floor_mask_.Check(c.alpha, c.bbox.tl(), points[k]);
    if (reason == Discard::kNone) {
      const bool trace = log_->should_log(spdlog::level::trace);  // then every feature, for the log
      const MatteShape shape = trace ? MeasureMatteShape(c.alpha, options_.noise.thick_px)
                                     : MeasureMatteShape(c.alpha, options_.noise);
      if (noise_.IsNoise(subjects[k], shape)) reason = Discard::kNoise;
      if (trace) {
        log_->trace(
            "{} frame {} subject {} box {}x{}+{}+{} shape area {:.0f} solidity {:.3f} thick {:.3f} "
            "largest {:.3f} mean_alpha {:.3f}",
            name_, frame.sequence, subjects[k], c.bbox.width, c.bbox.height, c.bbox.x, c.bbox.y,
            shape.area_px, shape.solidity, shape.thick_share, shape.largest_share,
            shape.mean_alpha);
      }
    }
    const bool still = stillness_.IsStill(subjects[k], frame.timestamp_ns, points[k]);
    if (reason == Discard::kNone && still) reason = Discard::kStill;
    if (reason == Discard::kNone) {
      const SpriteView view{&c.colour, &c.alpha, &c.shadow, c.bbox.tl(),
                            Eigen::Vector2d(c.contact_point.x, c.contact_point.y)};
      Rectifier::Refusal why;
      billboards[k] = from_above ? floor_rectifier_.Rectify(model_, view, &why)
                                 : rectifier_.Rectify(model_, view, &why);
      if (billboards[k] && side_by_side_.options().min_width_ratio > 0) {  // the rule is on
        looks[k] =
            MeasureMatteLook(billboards[k]->bgra, billboards[k]->px_per_m, side_by_side_.options());
      } else {
        reason = why.too_large ? Discard::kTooLarge : Discard::kNoGroundHit;
        if (why.too_large && (!last_too_large_log_ ||
                              Clock::now() - *last_too_large_log_ > std::chrono::seconds(10))) {
          last_too_large_log_ = Clock::now();
          log_->warn(
              "{} frame {}: a sprite's billboard would be {}x{} px at pipeline.px_per_m {}, over "
              "the {} px "
              "limit: refused as too_large (a subject this big needs a smaller px_per_m)",
              name_, frame.sequence, why.width_px, why.height_px, rectifier_.options().px_per_m,
              rectifier_.options().max_side_px);
        }
      }
    }
    usable[k] = reason == Discard::kNone;
    verdict_of[k] = verdicts_.size();
    verdicts_.push_back({&c, subjects[k], points[k], reason, merged[k]});
    if (usable[k]) {
      ++usable_total_;
    } else {
      ++stats_.discards[static_cast<size_t>(reason)];
    }
    if (log_->should_log(spdlog::level::trace)) {
      log_->trace("{} frame {} subject {} at ({:.4f}, {:.4f}) box {}x{}+{}+{} area {:.0f}: {}{}",
                  name_, frame.sequence, subjects[k], points[k].x(), points[k].y(), c.bbox.width,
                  c.bbox.height, c.bbox.x, c.bbox.y, c.area, DiscardName(reason),
                  merged[k] ? " (merged)" : "");
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
    // Two side by side (SideBySide): split and wide, or wide in a clip once seen split.
    const bool wide = !merged[k] && side_by_side_.IsWide(looks[k].width_m);
    const bool seen_split = batcher_.MarkedMerged(e.clip);
    const bool first_split = wide && looks[k].split && !seen_split;
    if (wide && (looks[k].split || seen_split)) {
      merged[k] = true;
      verdicts_[verdict_of[k]].merged = true;
    }
    if (!merged[k]) side_by_side_.AddOne(looks[k].width_m);
    s.merged = merged[k];
    s.matte_width_m = looks[k].width_m;
    batcher_.Add(e.clip, e.subject, std::move(s), out);
    if (first_split) {
      // The clip's wide sprites still held were the pair too, before a gap showed it.
      batcher_.MarkMerged(e.clip, side_by_side_.min_wide_m());
      log_->debug("{} frame {} subject {}: two side by side ({:.2f} m wide, one is {:.2f} m)",
                  name_, frame.sequence, subjects[k], looks[k].width_m,
                  side_by_side_.median_width_m());
    }
  }
  UpdateClipStats();
  stats_.seconds_rest += SecondsSince(rest_start);
}

void CameraPipeline::Finish(std::vector<ClipBatch>* out) {
  for (const int64_t clip : cutter_.CloseAll()) batcher_.Close(clip, out);
  batcher_.CloseAll(out);
  UpdateClipStats();
}

void CameraPipeline::Retarget(int64_t camera_id, std::vector<ClipBatch>* out) {
  Finish(out);
  batcher_.set_camera_id(camera_id);
  camera_id_ = camera_id;
}

void CameraPipeline::UpdateClipStats() {
  const uint64_t short_sprites = batcher_.short_clip_sprites();
  stats_.discards[static_cast<size_t>(Discard::kShortClip)] = short_sprites;
  stats_.discards[static_cast<size_t>(Discard::kNone)] = usable_total_ - short_sprites;
  stats_.stored_sprites = batcher_.stored_originals();
  stats_.merged_sprites = batcher_.stored_merged_originals();
  stats_.clips = batcher_.clips_completed();
}

}  // namespace ss
