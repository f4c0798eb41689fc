#pragma once
// A V4L2 capture device (/dev/videoN) as a FrameSource, on the kernel API
// directly: VIDIOC_* ioctls and mmap'ed streaming buffers, lent to the Frames
// without a copy and queued back when the last copy dies. Formats: YUYV,
// NV12, MJPEG, RGB24/BGR24, GREY and 8-bit Bayer. Exposure, gain and white
// balance are set with their automatic modes turned off and read back, so a
// keyer sees a fixed exposure. Frame::sequence is the driver's sequence
// number (gaps are drops) and Frame::timestamp_ns the driver's timestamp.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "capture/frame_source.h"

namespace ss {

struct V4l2Options {
  std::string device = "/dev/video0";
  std::string name;                         // SourceCamera::name ("" = the device path)
  int camera_index = 0;                     // Frame::camera of every frame
  std::optional<PixelFormat> pixel_format;  // unset = keep the driver's current format
  int width = 0;                            // 0 = keep the driver's current size
  int height = 0;
  double fps = 0.0;          // > 0: ask for this frame rate
  double exposure_us = 0.0;  // > 0: manual exposure (V4L2_CID_EXPOSURE_ABSOLUTE, 100 us units)
  int gain = -1;             // >= 0: auto gain off, V4L2_CID_GAIN
  int white_balance_k = 0;   // > 0: auto white balance off, colour temperature in kelvin
  bool white_balance_once = false;  // balance once (V4L2_CID_DO_WHITE_BALANCE), then hold it
  int buffers = 4;                  // mmap buffers requested
  int frame_timeout_ms = 2000;      // no frame for this long counts as one error
  // False with "FIELD: reason" lines in `why` (core/option_checks.h) for values out of range.
  bool IsValid(std::string* why) const;
};

// A station camera's keys of `source: v4l2` (CameraConfig::backend).
struct V4l2CameraKeys {
  std::string device;  // the device node, "/dev/video0"
  bool operator==(const V4l2CameraKeys&) const = default;
};

// A capture device found under /dev.
struct V4l2DeviceInfo {
  std::string path;                  // "/dev/video0"
  std::string driver;                // "uvcvideo", "vivid"
  std::string card;                  // the device's name
  std::string bus;                   // "usb-0000:00:14.0-1", "platform:vivid-000"
  std::vector<PixelFormat> formats;  // the ones SpriteStation reads
};

// Every /dev/video* node that can capture video (metadata and output nodes are skipped).
std::vector<V4l2DeviceInfo> ListV4l2Devices();

class V4l2Source : public FrameSource {
 public:
  // Opens, configures and starts streaming. WorkError naming the device when it
  // is missing, busy or fails; InputError naming the option when the device does
  // not offer a format, size or control that was asked for.
  explicit V4l2Source(V4l2Options options);
  ~V4l2Source() override;
  V4l2Source(const V4l2Source&) = delete;
  V4l2Source& operator=(const V4l2Source&) = delete;

  const std::vector<SourceCamera>& cameras() const override;
  // Throws WorkError when the device disappears mid-stream.
  std::optional<Frame> Next() override;
  void Stop() override;
  SourceStats stats() const override;

  // Reads a control's current value (V4L2_CID_*); std::nullopt when the device lacks it.
  std::optional<int32_t> control(uint32_t id) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace ss
