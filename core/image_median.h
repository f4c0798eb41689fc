#pragma once
// The per-pixel median of a stack of images: what stays put while a subject moves
// through it, e.g. the empty enclosure of a recording (its clean plate).
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace ss {

// 8-bit images of one size and channel count. Each output byte is the median of that byte
// over the stack (for an even count, the lower of the two middle values, so the result is
// always one of the inputs' values). InputError naming `what` when the stack is empty or
// its images differ in size, channels or depth.
cv::Mat PerPixelMedian(const std::vector<cv::Mat>& images, const std::string& what = "images");

}  // namespace ss
