#pragma once
// A libcamera camera as a FrameSource, on libcamera's C++ API as of 0.0.3
// (Debian 12): CameraManager, Camera::acquire, one VideoRecording stream,
// FrameBufferAllocator buffers mmap'ed once and lent to the Frames (the
// request is queued back when the last copy of a frame dies). Formats: YUYV,
// NV12, MJPEG, RGB888/BGR888. Exposure, gain, white balance and frame rate go
// in as libcamera controls, only those the camera lists; the others are named
// in ignored_controls() and the log. Frame::sequence is FrameMetadata::sequence
// (gaps are drops), Frame::timestamp_ns SensorTimestamp or the buffer timestamp.
#include <array>
#include <cstdint>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "capture/frame_source.h"

namespace ss {

enum class LibcameraWhiteBalance {
  kDevice,  // leave the camera's automatic white balance as it is
  kOnce,    // let it settle for `awb_settle_frames`, then AwbEnable = false
  kManual,  // AwbEnable = false, ColourGains = {red_gain, blue_gain}
};

struct LibcameraOptions {
  std::string camera_id;  // libcamera's camera id; "" = the first camera found
  std::string name;       // SourceCamera::name ("" = the camera id)
  int camera_index = 0;   // Frame::camera of every frame (>= 0)
  // yuyv, nv12, mjpeg, rgb8, bgr8; unset = the camera's default.
  std::optional<PixelFormat> pixel_format;
  int width = 0;     // px; 0 = the camera's default size (with height: both or neither)
  int height = 0;    // px; 0 = the camera's default size
  double fps = 0.0;  // frames per second; > 0: FrameDurationLimits fixed at 1/fps, 0 = leave it
  // microseconds; > 0: ExposureTime (AeEnable = false in any case: locked), 0 = leave it
  double exposure_us = 0.0;
  double analogue_gain = 0.0;  // > 0: AnalogueGain (linear, 1 = unity), 0 = leave it
  LibcameraWhiteBalance white_balance = LibcameraWhiteBalance::kDevice;  // device, once, manual
  double red_gain = 1.0;        // kManual: ColourGains red, linear (> 0)
  double blue_gain = 1.0;       // kManual: ColourGains blue, linear (> 0)
  int awb_settle_frames = 30;   // kOnce: frames auto white balance runs before it is locked (>= 1)
  int buffers = 4;              // requested (>= 2); libcamera may adjust
  int frame_timeout_ms = 2000;  // no frame for this long, milliseconds (>= 1), counts as one error
  // False with "FIELD: reason" lines in `why` (core/option_checks.h) for values out of range.
  bool IsValid(std::string* why) const;
};

// A camera libcamera can open.
struct LibcameraCameraInfo {
  std::string id;                    // what `camera_id` takes
  std::string model;                 // properties::Model, when the pipeline reports it
  std::string location;              // "front", "back", "external"
  std::vector<PixelFormat> formats;  // the ones SpriteStation reads
};

// Every camera libcamera's pipeline handlers find. WorkError when the manager does not start.
std::vector<LibcameraCameraInfo> ListLibcameraCameras();

// libcamera's format for ours (RGB888 is B,G,R in memory, so kBGR8); nullopt when it has none.
std::optional<std::string> LibcameraFormatName(PixelFormat format);
// Ours for libcamera's format name ("YUYV", "RGB888"...); nullopt when SpriteStation does not read
// it.
std::optional<PixelFormat> FromLibcameraFormatName(const std::string& name);

// What a camera lists of one control: its range when numeric (NaN when not).
struct LibcameraControlRange {
  double min = std::numeric_limits<double>::quiet_NaN();
  double max = std::numeric_limits<double>::quiet_NaN();
};

// The controls the options ask for, limited to the ones the camera lists.
struct LibcameraControlPlan {
  std::optional<bool> ae_enable;
  std::optional<int32_t> exposure_time_us;
  std::optional<float> analogue_gain;
  std::optional<bool> awb_enable;
  std::optional<std::array<float, 2>> colour_gains;                // red, blue
  std::optional<std::array<int64_t, 2>> frame_duration_limits_us;  // min, max
  bool lock_awb_after_settling = false;  // white balance kOnce and AwbEnable listed
  std::vector<std::string> ignored;  // "ColourGains (white_balance): the camera does not list it"
};

// Maps the options to controls. InputError naming the option when a listed
// control's range excludes the value asked for.
LibcameraControlPlan PlanLibcameraControls(
    const LibcameraOptions& options, const std::map<std::string, LibcameraControlRange>& listed);

class LibcameraSource : public FrameSource {
 public:
  // Acquires, configures and starts the camera. WorkError naming the camera when
  // it is absent (with the ids found) or busy; InputError naming the option for a
  // format or size the camera does not offer.
  explicit LibcameraSource(LibcameraOptions options);
  ~LibcameraSource() override;
  LibcameraSource(const LibcameraSource&) = delete;
  LibcameraSource& operator=(const LibcameraSource&) = delete;

  const std::vector<SourceCamera>& cameras() const override;
  // Throws WorkError when the camera disconnects mid-stream.
  std::optional<Frame> Next() override;
  void Stop() override;
  SourceStats stats() const override;

  // Controls asked for that the camera does not list, each with the option it came from.
  const std::vector<std::string>& ignored_controls() const;
  // The controls the camera lists ("AeEnable", "ExposureTime"...).
  const std::vector<std::string>& listed_controls() const;

 private:
  struct Impl;
  std::shared_ptr<Impl> impl_;
};

}  // namespace ss
