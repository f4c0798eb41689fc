#include "pipeline/run/clip_batcher.h"

#include <algorithm>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "core/option_checks.h"
#include "pipeline/rectify/floor_rectifier.h"

namespace ss {

bool ClipBatcherOptions::IsValid(std::string* why) const {
  OptionProblems check(why);
  check.Within(min_clip_frames, AtLeast(1), "min_clip_frames", "at least 1 frame");
  check.Within(batch_frames, AtLeast(1), "batch_frames", "at least 1 frame");
  check.Within(velocity_half_window, AtLeast(0), "velocity_half_window", "a number >= 0");
  return check.ok();
}
namespace {

// The bank keeps the shadow billboard-sized: the rectifier's square ground
// patch (centred on the contact point, rows running away from the camera) is
// cropped or padded to the billboard's size, centre on centre
// (docs/animation.md reads it back the same way).
cv::Mat FitShadow(const cv::Mat& patch, cv::Size size) {
  cv::Mat out = cv::Mat::zeros(size, CV_8UC1);
  if (patch.empty()) return out;
  const int dx = (size.width - 1) / 2 - (patch.cols - 1) / 2;
  const int dy = (size.height - 1) / 2 - (patch.rows - 1) / 2;
  const cv::Rect in_out =
      cv::Rect(dx, dy, patch.cols, patch.rows) & cv::Rect(0, 0, size.width, size.height);
  if (in_out.empty()) return out;
  patch(in_out - cv::Point(dx, dy)).copyTo(out(in_out));
  return out;
}

SpriteRecord OriginalRecord(const MadeSprite& s, const Eigen::Vector2d& velocity) {
  SpriteRecord r;
  r.frame = s.frame;
  r.timestamp_ns = s.timestamp_ns;
  r.ground_x_m = s.billboard.point_in_ground.x();
  r.ground_y_m = s.billboard.point_in_ground.y();
  r.velocity_x_m_s = velocity.x();
  r.velocity_y_m_s = velocity.y();
  r.mean_r = s.description.mean_r;
  r.mean_g = s.description.mean_g;
  r.mean_b = s.description.mean_b;
  r.area_px = s.description.area_px;
  r.eccentricity = s.description.eccentricity;
  r.bbox_in_image = s.bbox_in_image;
  r.billboard_width_px = s.billboard.bgra.cols;
  r.billboard_height_px = s.billboard.bgra.rows;
  r.px_per_m = s.billboard.px_per_m;
  r.anchor_x_px = s.billboard.anchor_px.x();
  r.anchor_y_px = s.billboard.anchor_px.y();
  r.kind = s.billboard.kind;
  r.heading_rad = s.billboard.heading_rad;
  r.pixels.bgra = s.billboard.bgra;
  r.pixels.shadow = FitShadow(s.billboard.shadow, s.billboard.bgra.size());
  // In the sprite's own row batch: the bank stores the tag in the transaction that stores the
  // sprite, so no sprite is ever stored without its mark (the mirror copies the original's tags).
  if (s.merged) r.tags.push_back(kMergedTag);
  return r;
}

// The mirrored copy: same place and time, the image flipped, velocity mirrored
// across the billboard's vertical axis. Its pixels are its original's (the bank
// flips them on load).
SpriteRecord MirrorRecord(const SpriteRecord& original, const MadeSprite& s) {
  SpriteRecord m = original;
  m.mirrored = true;
  m.pixels = {};
  m.anchor_x_px = (original.billboard_width_px - 1) - original.anchor_x_px;
  const Eigen::Vector2d v = Rectifier::MirrorVelocity(
      s.billboard, Eigen::Vector2d(original.velocity_x_m_s, original.velocity_y_m_s));
  m.velocity_x_m_s = v.x();
  m.velocity_y_m_s = v.y();
  return m;
}

}  // namespace

ClipBatcher::ClipBatcher(int64_t camera_id, ClipBatcherOptions options)
    : camera_id_(camera_id), options_(options) {
  if (std::string why; !options_.IsValid(&why)) throw InputError("clip batcher options", why);
}

void ClipBatcher::Add(int64_t clip, int subject, MadeSprite sprite, std::vector<ClipBatch>* out) {
  auto [it, inserted] = clips_.try_emplace(clip);
  Open& open = it->second;
  if (inserted) {
    open.subject = subject;
    open.first_frame = sprite.frame;
  } else if (sprite.frame != open.first_frame + static_cast<int64_t>(open.points.size())) {
    throw WorkError("clip " + std::to_string(clip), "frames of a clip must be consecutive");
  }
  open.timestamps_ns.push_back(sprite.timestamp_ns);
  open.points.emplace_back(sprite.billboard.point_in_ground.x(),
                           sprite.billboard.point_in_ground.y());
  open.pending.push_back(std::move(sprite));

  const size_t length = open.points.size();
  // At least one sprite stays back so that the closing batch is never empty.
  size_t hold = std::max<size_t>(1, static_cast<size_t>(options_.velocity_half_window));
  if (open.pending.front().billboard.kind == SpriteKind::kFloor) {
    hold = std::max(hold, kHeadingLookahead);
  }
  if (length < static_cast<size_t>(options_.min_clip_frames)) return;
  if (open.pending.size() >= static_cast<size_t>(options_.batch_frames) + hold) {
    Emit(open, open.pending.size() - hold, false, out);
  }
}

void ClipBatcher::MarkMerged(int64_t clip, double min_width_m) {
  const auto it = clips_.find(clip);
  if (it == clips_.end()) return;
  it->second.marked_merged = true;
  for (MadeSprite& s : it->second.pending) s.merged = s.merged || s.matte_width_m >= min_width_m;
}

bool ClipBatcher::MarkedMerged(int64_t clip) const {
  const auto it = clips_.find(clip);
  return it != clips_.end() && it->second.marked_merged;
}

void ClipBatcher::Close(int64_t clip, std::vector<ClipBatch>* out) {
  const auto it = clips_.find(clip);
  if (it == clips_.end()) return;
  Open& open = it->second;
  if (open.points.size() < static_cast<size_t>(options_.min_clip_frames)) {
    short_clip_sprites_ += open.pending.size();
  } else {
    Emit(open, open.pending.size(), true, out);
    ++clips_completed_;
  }
  clips_.erase(it);
}

void ClipBatcher::CloseAll(std::vector<ClipBatch>* out) {
  while (!clips_.empty()) Close(clips_.begin()->first, out);
}

namespace {

// Moves a floor sprite's place `ahead_m` along its heading: the point on the floor, the anchor
// in its image (up is ahead) and its shadow patch, centred on the place (its content moves back).
void MoveFloorPlace(double ahead_m, Billboard* b) {
  if (ahead_m == 0) return;
  const double px = ahead_m * b->px_per_m;
  b->point_in_ground += ahead_m * Eigen::Vector3d(b->toward_camera.x(), b->toward_camera.y(), 0);
  b->anchor_px.y() -= px;
  if (!b->shadow.empty()) {
    const cv::Matx23d shift(1, 0, 0, 0, 1, px);
    cv::Mat moved;
    cv::warpAffine(b->shadow, moved, shift, b->shadow.size(), cv::INTER_LINEAR, cv::BORDER_CONSTANT,
                   cv::Scalar(0));
    b->shadow = moved;
  }
}

}  // namespace

void ClipBatcher::Emit(Open& open, size_t count, bool complete, std::vector<ClipBatch>* out) {
  const size_t first_index = open.points.size() - open.pending.size();
  ClipBatch batch;
  batch.clip.camera_id = camera_id_;
  batch.clip.track_id = open.subject;
  batch.clip.first_frame = open.first_frame;
  batch.clip.last_frame = open.first_frame + static_cast<int64_t>(first_index + count) - 1;
  batch.clip.complete = complete;
  batch.sprites.reserve(count * (options_.mirrors ? 2 : 1));
  // The emitted frames' velocities, each from its own +-window (not the whole clip's); floor
  // sprites' headings read every held frame's.
  const bool floor = count > 0 && open.pending.front().billboard.kind == SpriteKind::kFloor;
  std::vector<Eigen::Vector2d> velocities(floor ? open.pending.size() : count);
  for (size_t k = 0; k < velocities.size(); ++k) {
    velocities[k] =
        EstimateVelocity(open.timestamps_ns, open.points, static_cast<int>(first_index + k),
                         options_.velocity_half_window);
  }
  if (floor) {
    // Head first: the signs of every frame held, those handed out now kept.
    std::vector<HeadingCue> cues(open.pending.size());
    for (size_t k = 0; k < cues.size(); ++k) {
      const Billboard& b = open.pending[k].billboard;
      cues[k] = {b.heading_rad, b.elongation, velocities[k]};
    }
    const std::vector<bool> flip = ResolveHeadings(cues, {}, open.last_heading);
    // The place: the outline's centre (steady, but the head pulls it ahead of where the animal
    // rests its weight) moved ahead by the median offset of the body's thickest part over the
    // frames within kHeadingLookahead (one frame's offset jitters: the path's second
    // difference went from 0.61 to 1.35 mm with it unsmoothed, bench/RESULTS.md).
    std::vector<double> aheads = open.aheads;  // those handed out, then every frame held
    const size_t handed = aheads.size();
    for (size_t k = 0; k < open.pending.size(); ++k) {
      const double a = open.pending[k].billboard.thickest_ahead_m;
      aheads.push_back(flip[k] ? -a : a);
    }
    const auto window = static_cast<ptrdiff_t>(kHeadingLookahead);
    std::vector<double> near;
    for (size_t k = 0; k < count; ++k) {
      Billboard& b = open.pending[k].billboard;
      if (flip[k]) b = FloorRectifier::TurnHalf(b);
      const auto at = static_cast<ptrdiff_t>(handed + k);
      near.assign(aheads.begin() + std::max<ptrdiff_t>(0, at - window),
                  aheads.begin() + std::min<ptrdiff_t>(std::ssize(aheads), at + window + 1));
      std::nth_element(near.begin(), near.begin() + std::ssize(near) / 2, near.end());
      MoveFloorPlace(near[near.size() / 2], &b);
    }
    open.last_heading = open.pending[count - 1].billboard.heading_rad;
    open.aheads.assign(
        aheads.begin() + std::max<ptrdiff_t>(0, static_cast<ptrdiff_t>(handed + count) - window),
        aheads.begin() + static_cast<ptrdiff_t>(handed + count));
  }
  for (size_t k = 0; k < count; ++k) {
    const MadeSprite& s = open.pending[k];
    stored_merged_originals_ += s.merged ? 1 : 0;
    SpriteRecord original = OriginalRecord(s, velocities[k]);
    if (options_.mirrors) {
      SpriteRecord mirror = MirrorRecord(original, s);
      batch.sprites.push_back(std::move(original));
      batch.sprites.push_back(std::move(mirror));
    } else {
      batch.sprites.push_back(std::move(original));
    }
  }
  open.pending.erase(open.pending.begin(),
                     open.pending.begin() + static_cast<std::ptrdiff_t>(count));
  stored_originals_ += count;
  open.started = true;
  if (!batch.sprites.empty() || complete) out->push_back(std::move(batch));
}

void ClipBatcher::set_camera_id(int64_t camera_id) {
  if (!clips_.empty())
    throw WorkError("clip batcher", "cannot change the bank camera while clips are open");
  camera_id_ = camera_id;
}

}  // namespace ss
