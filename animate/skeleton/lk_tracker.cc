#include "animate/skeleton/lk_tracker.h"

#include <cmath>
#include <set>

#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include "core/error.h"
#include "core/option_checks.h"

namespace ss {

bool LkOptions::IsValid(std::string* why) const {
  OptionProblems check(why);
  check.Within(window_px, AtLeast(5), "window_px", "at least 5 pixels");
  check.Within(pyramid_levels, Between(0, 8), "pyramid_levels", "0..8 levels");
  check.Within(max_iterations, AtLeast(1), "max_iterations", "at least 1");
  check.Within(epsilon, Positive(), "epsilon", "a number > 0");
  check.Within(max_forward_backward_px, Positive(), "max_forward_backward_px",
               "a number > 0 pixels");
  check.Within(interpolation_context, AtLeast(1), "interpolation_context", "at least 1");
  return check.ok();
}

LkJointTracker::LkJointTracker(SkeletonDef skeleton, LkOptions options)
    : skeleton_(std::move(skeleton)), options_(options) {
  std::string why;
  if (!options_.IsValid(&why)) throw InputError("tracking options", why);
  seen_.resize(skeleton_.joints.size());
  result_.sequence.skeleton = skeleton_;
}

void LkJointTracker::AddFrame(const cv::Mat& image, const std::vector<bool>& occluded,
                              const SkeletonFrame* given) {
  const std::string where = "tracking frame " + std::to_string(frame_);
  if (image.empty() || image.depth() != CV_8U || (image.channels() != 1 && image.channels() != 3)) {
    throw InputError(where, "expected an 8-bit grey or BGR image");
  }
  if (frame_ == 0) {
    size_ = image.size();
  } else if (image.size() != size_) {
    throw InputError(where, "image size changed within the clip");
  }
  const size_t joints = skeleton_.joints.size();
  if (!occluded.empty() && occluded.size() != joints) {
    throw InputError(where, "occlusion marks for " + std::to_string(occluded.size()) +
                                " joints, skeleton '" + skeleton_.name + "' has " +
                                std::to_string(joints));
  }
  if (given && given->joints.size() != joints) {
    throw InputError(where, "given joints: " + std::to_string(given->joints.size()) +
                                ", skeleton '" + skeleton_.name + "' has " +
                                std::to_string(joints));
  }
  if (frame_ == 0 && !given) throw InputError(where, "the first frame needs the user's joints");
  cv::Mat grey;
  if (image.channels() == 3) {
    cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  } else {
    grey = image.clone();
  }
  const cv::Size window(options_.window_px, options_.window_px);
  std::vector<cv::Mat> pyramid;
  const int levels = cv::buildOpticalFlowPyramid(grey, pyramid, window, options_.pyramid_levels);

  SkeletonFrame out = EmptySkeletonFrame(skeleton_, frame_);
  std::vector<bool> marks = occluded.empty() ? std::vector<bool>(joints, false) : occluded;
  std::map<int, std::vector<int>> by_source;  // frame last seen -> joints to track from it
  for (size_t j = 0; j < joints; ++j) {
    if (given && given->joints[j].present) {
      out.joints[j] = {given->joints[j].x_px, given->joints[j].y_px, 1.0f, true, false};
      seen_[j] = {{given->joints[j].x_px, given->joints[j].y_px}, frame_};
      marks[j] = false;
      continue;
    }
    if (marks[j] || seen_[j].frame < 0) continue;
    by_source[seen_[j].frame].push_back(static_cast<int>(j));
  }
  const cv::TermCriteria criteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS,
                                  options_.max_iterations, options_.epsilon);
  for (const auto& [source_frame, list] : by_source) {
    std::vector<cv::Mat> source_pyramid;
    int source_levels = levels;
    if (source_frame == frame_ - 1) {
      source_pyramid = previous_pyramid_;
    } else {
      source_levels = cv::buildOpticalFlowPyramid(kept_.at(source_frame), source_pyramid, window,
                                                  options_.pyramid_levels);
    }
    const int use_levels = std::min(levels, source_levels);
    std::vector<cv::Point2f> from, to, back;
    for (int j : list) from.push_back(seen_[j].position);
    std::vector<uchar> status, back_status;
    std::vector<float> error;
    cv::calcOpticalFlowPyrLK(source_pyramid, pyramid, from, to, status, error, window, use_levels,
                             criteria);
    cv::calcOpticalFlowPyrLK(pyramid, source_pyramid, to, back, back_status, error, window,
                             use_levels, criteria);
    for (size_t i = 0; i < list.size(); ++i) {
      const int j = list[i];
      const bool inside =
          to[i].x >= 0 && to[i].y >= 0 && to[i].x < size_.width && to[i].y < size_.height;
      if (!status[i] || !back_status[i] || !inside) {
        result_.failures.push_back({frame_, j, "lost", -1.0f});
        continue;
      }
      const float fb = static_cast<float>(cv::norm(back[i] - from[i]));
      if (fb > options_.max_forward_backward_px) {
        result_.failures.push_back({frame_, j, "forward-backward", fb});
        continue;
      }
      out.joints[j] = {to[i].x, to[i].y, 1.0f, true, false};
      seen_[j] = {to[i], frame_};
    }
  }
  // Keep the previous frame if a joint was last seen there; drop frames no joint needs.
  std::set<int> needed;
  for (const auto& s : seen_) {
    if (s.frame >= 0 && s.frame < frame_) needed.insert(s.frame);
  }
  if (frame_ > 0 && needed.count(frame_ - 1)) kept_[frame_ - 1] = previous_grey_;
  for (auto it = kept_.begin(); it != kept_.end();)
    it = needed.count(it->first) ? std::next(it) : kept_.erase(it);
  previous_grey_ = grey;
  previous_pyramid_ = std::move(pyramid);
  occluded_.push_back(marks);
  result_.sequence.frames.push_back(std::move(out));
  ++frame_;
}

TrackingResult LkJointTracker::Finish() {
  auto& frames = result_.sequence.frames;
  const int n = static_cast<int>(frames.size());
  const int context = options_.interpolation_context;
  for (size_t j = 0; j < skeleton_.joints.size(); ++j) {
    auto at = [&](int f) -> const JointSample& { return frames[f].joints[j]; };
    auto seen = [&](int f) { return f >= 0 && f < n && at(f).present && !at(f).interpolated; };
    for (int a = 0; a < n; ++a) {
      if (!occluded_[a][j] || at(a).present) continue;
      int b = a;
      while (b + 1 < n && occluded_[b + 1][j] && !at(b + 1).present) ++b;
      const int before = a - 1, after = b + 1;
      if (seen(before) && seen(after)) {
        // Cubic Hermite from `before` to `after`; the tangents are the mean velocities over
        // up to `context` tracked frames on each side (linear where there are none).
        const cv::Point2f p0(at(before).x_px, at(before).y_px), p1(at(after).x_px, at(after).y_px);
        const float span = static_cast<float>(after - before);
        cv::Point2f v0 = (p1 - p0) / span, v1 = v0;
        for (int c = context; c >= 1; --c) {
          if (seen(before - c)) {
            v0 = (p0 - cv::Point2f(at(before - c).x_px, at(before - c).y_px)) /
                 static_cast<float>(c);
            break;
          }
        }
        for (int c = context; c >= 1; --c) {
          if (seen(after + c)) {
            v1 = (cv::Point2f(at(after + c).x_px, at(after + c).y_px) - p1) / static_cast<float>(c);
            break;
          }
        }
        for (int f = a; f <= b; ++f) {
          const float u = static_cast<float>(f - before) / span;
          const float h00 = 2 * u * u * u - 3 * u * u + 1, h10 = u * u * u - 2 * u * u + u;
          const float h01 = -2 * u * u * u + 3 * u * u, h11 = u * u * u - u * u;
          const cv::Point2f p = h00 * p0 + h10 * span * v0 + h01 * p1 + h11 * span * v1;
          frames[f].joints[j] = {p.x, p.y, 0.5f, true, true};
        }
      }
      a = b;
    }
  }
  TrackingResult out = std::move(result_);
  result_ = {};
  result_.sequence.skeleton = skeleton_;
  return out;
}

TrackingResult TrackJoints(const std::vector<cv::Mat>& images, const SkeletonFrame& first,
                           const std::vector<bool>& occluded_frames, const SkeletonDef& skeleton,
                           const LkOptions& options) {
  if (!occluded_frames.empty() && occluded_frames.size() != images.size()) {
    throw InputError("occluded frames", "one mark per image expected");
  }
  LkJointTracker tracker(skeleton, options);
  const std::vector<bool> all(skeleton.joints.size(), true);
  for (size_t i = 0; i < images.size(); ++i) {
    const bool occluded = !occluded_frames.empty() && occluded_frames[i];
    tracker.AddFrame(images[i], occluded && i > 0 ? all : std::vector<bool>{},
                     i == 0 ? &first : nullptr);
  }
  return tracker.Finish();
}

}  // namespace ss
