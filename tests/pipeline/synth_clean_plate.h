#pragma once
// The empty enclosure as a synthetic camera's sensor captures it (noise, gains, pixel format):
// what the keyer tests train the keyer on, as a station learns its empty enclosure.
#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

#include "core/frame.h"
#include "synth/renderer.h"

namespace ss::testing {

inline std::vector<cv::Mat> CleanPlateFrames(const synth::CameraRenderer& renderer,
                                             const synth::Sensor& sensor, PixelFormat format,
                                             int count = 4) {
  const cv::Mat& plate = renderer.clean_plate();
  std::vector<cv::Mat> frames;
  frames.reserve(static_cast<size_t>(count));
  for (int i = 0; i < count; ++i) {
    frames.push_back(ToBgr(Frame::Owned(format, plate.cols, plate.rows,
                                        sensor.Capture(plate, format, 1'000'000 + i))));
  }
  return frames;
}

}  // namespace ss::testing
