#pragma once
// Semi-automatic skeleton extraction (seed 003 §2.1): the user gives the joints in the
// first frame, pyramidal Lucas-Kanade optical flow (cv::calcOpticalFlowPyrLK) carries them
// from frame to frame, joints the user marks occluded are not tracked and are interpolated
// afterwards from the frames before and after the occlusion. A joint whose flow fails
// (status 0, or a forward-backward error above the threshold) is reported for that frame,
// left missing there, and tracked again from its last good frame.
#include <map>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "animate/skeleton/skeleton.h"

namespace ss {

struct LkOptions {
  int window_px = 21;      // side of the search window at each level
  int pyramid_levels = 3;  // levels above the image (0 = no pyramid)
  int max_iterations = 30;
  double epsilon = 0.01;                 // pixels: the iteration stops below this update
  float max_forward_backward_px = 1.0f;  // tracking back must land this close to the start
  int interpolation_context = 2;         // frames each side whose motion shapes the interpolation
  // False with "FIELD: reason" lines in `why` (core/option_checks.h) for values out of range.
  bool IsValid(std::string* why) const;
};

struct TrackingFailure {
  int frame = 0;  // index into the sequence
  int joint = 0;
  std::string reason;              // "lost" (flow status 0) or "forward-backward"
  float forward_backward_px = -1;  // the error, when the flow converged both ways
};

struct TrackingResult {
  SkeletonSequence sequence;
  std::vector<TrackingFailure> failures;
};

// Feed frames in order (any 8-bit grey or BGR cv::Mat, e.g. decoded by the replay), then
// Finish(). Memory: the previous frame's pyramid and the frames occluded joints were last
// seen in.
class LkJointTracker {
 public:
  explicit LkJointTracker(SkeletonDef skeleton, LkOptions options = {});

  // The next frame. `occluded`: per joint, true when the user marks it occluded here (empty:
  // none). `given`: joints the user placed in this frame (required for the first frame;
  // later, present joints re-seed the tracking). Throws InputError for a bad image, a
  // wrong joint count or a first frame without given joints.
  void AddFrame(const cv::Mat& image, const std::vector<bool>& occluded = {},
                const SkeletonFrame* given = nullptr);

  // Interpolates the occlusions and returns the sequence (frame numbers 0, 1, ...).
  TrackingResult Finish();

 private:
  struct Seen {
    cv::Point2f position;
    int frame = -1;  // where it was last tracked or given; -1 never
  };

  SkeletonDef skeleton_;
  LkOptions options_;
  int frame_ = 0;
  cv::Size size_;
  std::vector<cv::Mat> previous_pyramid_;
  std::map<int, cv::Mat> kept_;  // grey frames that an occluded or failed joint was last seen in
  cv::Mat previous_grey_;
  std::vector<Seen> seen_;
  std::vector<std::vector<bool>> occluded_;  // per frame, per joint
  TrackingResult result_;
};

// Tracks a whole clip held in memory; `occluded_frames[i]` marks every joint of frame i.
TrackingResult TrackJoints(const std::vector<cv::Mat>& images, const SkeletonFrame& first,
                           const std::vector<bool>& occluded_frames, const SkeletonDef& skeleton,
                           const LkOptions& options = {});

}  // namespace ss
