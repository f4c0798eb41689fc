#include "import/empty_scene.h"

#include <algorithm>

#include <opencv2/imgproc.hpp>

#include "core/error.h"

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

cv::Mat PerPixelMedian(const std::vector<cv::Mat>& frames) {
  if (frames.empty()) throw WorkError("median plate", "no frames to take the median of");
  const cv::Mat& first = frames.front();
  for (const cv::Mat& f : frames) {
    if (f.type() != CV_8UC3 || f.size() != first.size() || !f.isContinuous()) {
      throw WorkError("median plate", "frames differ in size or type");
    }
  }
  cv::Mat median(first.size(), CV_8UC3);
  const size_t values = first.total() * 3, n = frames.size();
  std::vector<const uint8_t*> planes;
  for (const cv::Mat& f : frames) planes.push_back(f.data);
  uint8_t* out = median.data;
  // A histogram per value would be faster for many frames; a few dozen sort quickly enough.
  std::vector<uint8_t> column(n);
  for (size_t v = 0; v < values; ++v) {
    for (size_t i = 0; i < n; ++i) column[i] = planes[i][v];
    std::nth_element(column.begin(), column.begin() + n / 2, column.end());
    out[v] = column[n / 2];
  }
  return median;
}

cv::Mat WithoutForeground(const cv::Mat& frame, const cv::Mat& plate, int threshold_levels, int grow_px,
                          double* replaced_share) {
  cv::Mat diff;
  cv::absdiff(frame, plate, diff);
  std::vector<cv::Mat> channels;
  cv::split(diff, channels);
  cv::Mat most = cv::max(channels[0], cv::max(channels[1], channels[2]));
  cv::Mat mask = most > threshold_levels;
  if (grow_px > 0) {
    cv::dilate(mask, mask, cv::getStructuringElement(cv::MORPH_ELLIPSE, {2 * grow_px + 1, 2 * grow_px + 1}));
  }
  cv::Mat out = frame.clone();
  plate.copyTo(out, mask);
  if (replaced_share != nullptr) *replaced_share = static_cast<double>(cv::countNonZero(mask)) / mask.total();
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
