#include "import/empty_scene.h"

#include <algorithm>
#include <cstdlib>

#include "core/error.h"
#include "core/image_median.h"

namespace ss {

void EvenFrameSampler::Offer(const cv::Mat& bgr) {
  const int64_t n = offered_++;
  if (n % stride_ != 0) return;
  frames_.push_back(bgr.clone());
  if (static_cast<int>(frames_.size()) > 2 * wanted_) {
    std::vector<cv::Mat> kept;
    for (size_t i = 0; i < frames_.size(); i += 2) kept.push_back(std::move(frames_[i]));
    frames_ = std::move(kept);
    stride_ *= 2;
  }
}

RobustBackground MedianAndSpread(const std::vector<cv::Mat>& frames) {
  if (frames.empty()) throw WorkError("median plate", "no frames to take the median of");
  for (const cv::Mat& f : frames) {
    if (f.type() != CV_8UC3 || f.size() != frames.front().size()) {
      throw WorkError("median plate", "frames differ in size or type");
    }
  }
  // The median, then the median absolute deviation from it (scaled to a normal sigma).
  RobustBackground b;
  b.median = PerPixelMedian(frames, "median plate");
  std::vector<cv::Mat> deviations(frames.size());
  for (size_t i = 0; i < frames.size(); ++i) cv::absdiff(frames[i], b.median, deviations[i]);
  PerPixelMedian(deviations, "median plate").convertTo(b.spread, CV_32FC3, 1.4826);
  return b;
}

cv::Mat Winsorized(const cv::Mat& frame, const RobustBackground& background, double k,
                   double* kept_share) {
  if (frame.size() != background.median.size() || frame.type() != CV_8UC3 ||
      !frame.isContinuous()) {
    throw WorkError("median plate", "frame differs from the plate in size or type");
  }
  cv::Mat out(frame.size(), CV_8UC3);
  const size_t values = frame.total() * 3;
  const uint8_t* in = frame.data;
  const uint8_t* median = background.median.data;
  const float* spread = background.spread.ptr<float>();
  uint8_t* o = out.data;
  size_t kept = 0;
  for (size_t v = 0; v < values; ++v) {
    const float limit = std::max(1.0f, static_cast<float>(k) * spread[v]);
    const float d = static_cast<float>(in[v]) - median[v];
    const float clamped = std::clamp(d, -limit, limit);
    kept += clamped == d;
    o[v] = cv::saturate_cast<uint8_t>(median[v] + clamped);
  }
  if (kept_share != nullptr) *kept_share = static_cast<double>(kept) / values;
  return out;
}

std::vector<int> EvenIndices(int n, int count) {
  std::vector<int> out;
  if (n <= 0) return out;
  for (int i = 0; i < count; ++i) {
    out.push_back(static_cast<int>((static_cast<int64_t>(i) * n + n / 2) / count) % n);
  }
  return out;
}

}  // namespace ss
