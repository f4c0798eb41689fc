#pragma once
// The empty scene the clean-plate keyer learns from, for footage that has no
// empty stretch: a per-pixel median over frames spread across the video (a
// walker covers a pixel for a moment, the floor is there the rest of the time),
// and "empty" frames made from real ones by putting the median where they
// differ from it, so each keeps the camera's own noise on the background.
#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

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

// The per-pixel, per-channel median of equally sized CV_8UC3 frames (the upper
// of the two middle values for an even count).
cv::Mat PerPixelMedian(const std::vector<cv::Mat>& frames);

// `frame` with every pixel that differs from `plate` by more than
// `threshold_levels` in a channel, grown by `grow_px`, replaced by the plate's.
// `replaced_share` (optional) gets the fraction of pixels replaced.
cv::Mat WithoutForeground(const cv::Mat& frame, const cv::Mat& plate, int threshold_levels, int grow_px,
                          double* replaced_share = nullptr);

// `count` indices spread evenly over 0..n-1 (each used once when n >= count).
std::vector<int> EvenIndices(int n, int count);

}  // namespace ss
