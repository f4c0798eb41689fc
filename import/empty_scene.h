#pragma once
// The empty scene the clean-plate keyer learns from, for footage that has no
// empty stretch: a per-pixel median over frames spread across the video (a
// walker covers a pixel for a moment, the floor is there the rest of the time),
// and "empty" frames made from real ones by pulling each value to within a few
// robust spreads of the median, so each keeps the camera's own noise and the
// background's own motion but loses the walkers.
#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

namespace ss {

// Keeps an even spread of the frames offered one by one, of unknown count:
// every `stride`-th, the stride doubling (every other kept frame dropped)
// whenever more than 2 x `wanted` are held. Ends with wanted..2 x wanted frames
// (fewer only when fewer were offered).
class EvenFrameSampler {
 public:
  explicit EvenFrameSampler(int wanted) : wanted_(wanted < 1 ? 1 : wanted) {}
  void Offer(const cv::Mat& bgr);  // copied when kept
  const std::vector<cv::Mat>& frames() const { return frames_; }
  int64_t offered() const { return offered_; }

 private:
  int wanted_;
  int64_t stride_ = 1;
  int64_t offered_ = 0;
  std::vector<cv::Mat> frames_;
};

// The background a set of frames agrees on, per pixel and channel: the median
// (the upper of the two middle values for an even count) and the spread around
// it, 1.4826 x the median absolute deviation (the noise std for Gaussian noise;
// unmoved by a walker who covers the pixel in under half the frames, large
// where the background itself moves: a flag, leaves, a fluttering tape).
struct RobustBackground {
  cv::Mat median;  // CV_8UC3
  cv::Mat spread;  // CV_32FC3, levels
};
// Of equally sized CV_8UC3 frames (at least one).
RobustBackground MedianAndSpread(const std::vector<cv::Mat>& frames);

// `frame` with each value pulled to within `k` spreads (at least 1 level) of the
// median: a walker's pixels become background, the background's own noise and
// motion stay, so a keyer learning from such frames learns how much each pixel
// moves. `kept_share` (optional) gets the share of values left as they were.
cv::Mat Winsorized(const cv::Mat& frame, const RobustBackground& background, double k,
                   double* kept_share = nullptr);

// `count` indices spread evenly over 0..n-1 (each used once when n >= count).
std::vector<int> EvenIndices(int n, int count);

}  // namespace ss
