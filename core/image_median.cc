#include "core/image_median.h"

#include <algorithm>

#include "core/error.h"

namespace ss {

cv::Mat PerPixelMedian(const std::vector<cv::Mat>& images, const std::string& what) {
  if (images.empty()) throw InputError(what, "no image to take the median of");
  const cv::Mat& first = images.front();
  if (first.empty() || first.depth() != CV_8U) throw InputError(what, "expected 8-bit images");
  for (size_t i = 1; i < images.size(); ++i) {
    if (images[i].size() != first.size() || images[i].type() != first.type()) {
      throw InputError(what, "image " + std::to_string(i) + " is " +
                                 std::to_string(images[i].cols) + "x" +
                                 std::to_string(images[i].rows) + " with " +
                                 std::to_string(images[i].channels()) + " channel(s), image 0 " +
                                 std::to_string(first.cols) + "x" + std::to_string(first.rows) +
                                 " with " + std::to_string(first.channels()));
    }
  }
  const size_t n = images.size(), middle = (n - 1) / 2;
  const int row_bytes = first.cols * first.channels();
  cv::Mat out(first.size(), first.type());
  std::vector<const uint8_t*> rows(n);
  std::vector<uint8_t> values(n);
  for (int y = 0; y < first.rows; ++y) {
    for (size_t i = 0; i < n; ++i) rows[i] = images[i].ptr<uint8_t>(y);
    uint8_t* dst = out.ptr<uint8_t>(y);
    for (int x = 0; x < row_bytes; ++x) {
      for (size_t i = 0; i < n; ++i) values[i] = rows[i][x];
      std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(middle),
                       values.end());
      dst[x] = values[middle];
    }
  }
  return out;
}

}  // namespace ss
