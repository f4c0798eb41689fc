// Runs inside the qemu guest (tests/vivid/vivid_test.cc builds the initramfs):
// drives the V4L2 backend against the kernel's vivid driver and prints one
// "CHECK <name> ok|FAIL <detail>" line per check, then "PROBE_DONE". Statically
// linked, so the guest needs nothing but busybox and the media modules.
#include <linux/videodev2.h>

#include <cstdio>
#include <cstring>
#include <exception>
#include <string>

#include "capture/v4l2/v4l2_source.h"
#include "core/error.h"

namespace {

int failures = 0;

void Check(const std::string& name, bool ok, const std::string& detail) {
  std::printf("CHECK %s %s %s\n", name.c_str(), ok ? "ok" : "FAIL", detail.c_str());
  std::fflush(stdout);
  if (!ok) ++failures;
}

bool Contains(const std::string& s, const std::string& part) {
  return s.find(part) != std::string::npos;
}

// Mean luma of a column band of a YUYV frame's lower half (Y at every even
// byte), below the text vivid draws in the top-left corner.
double MeanLuma(const ss::Frame& f, int x0, int x1) {
  double sum = 0;
  long n = 0;
  for (int y = f.height / 2; y < f.height; y += 4) {
    const uint8_t* row = f.data + static_cast<size_t>(y) * f.width * 2;
    for (int x = x0; x < x1; ++x, ++n) sum += row[2 * x];
  }
  return n > 0 ? sum / static_cast<double>(n) : 0.0;
}

// Expects constructing a source with `options` to throw E whose message holds `part`.
template <typename E>
void ExpectError(const std::string& name, const ss::V4l2Options& options, const std::string& part) {
  try {
    ss::V4l2Source source(options);
    Check(name, false, "no error");
  } catch (const E& e) {
    Check(name, Contains(e.what(), part), e.what());
  } catch (const std::exception& e) {
    Check(name, false, std::string("wrong error kind: ") + e.what());
  }
}

void StreamYuyv() {
  ss::V4l2Options o;
  o.device = "/dev/video0";
  o.pixel_format = ss::PixelFormat::kYUYV;
  o.width = 640;
  o.height = 480;
  o.gain = 42;
  ss::V4l2Source source(o);
  const auto& cam = source.cameras().at(0);
  Check("yuyv_format",
        cam.format == ss::PixelFormat::kYUYV && cam.width == 640 && cam.height == 480,
        ss::PixelFormatName(cam.format) + " " + std::to_string(cam.width) + "x" +
            std::to_string(cam.height) + " fps " + std::to_string(cam.fps));
  const auto gain = source.control(V4L2_CID_GAIN);
  const auto autogain = source.control(V4L2_CID_AUTOGAIN);
  Check("gain_locked", gain && *gain == 42 && autogain && *autogain == 0,
        "gain " + std::to_string(gain.value_or(-1)) + " autogain " +
            std::to_string(autogain.value_or(-1)));

  // A second opener while streaming: the device is busy.
  ss::V4l2Options again = o;
  again.gain = -1;
  ExpectError<ss::WorkError>("busy_device", again, "busy");

  int frames = 0;
  bool sizes_ok = true;
  bool sequence_ok = true;
  bool time_ok = true;
  uint64_t first_sequence = 0, last_sequence = 0;
  int64_t first_ns = 0, last_ns = 0;
  double left = 0, right = 0;
  for (; frames < 30; ++frames) {
    auto f = source.Next();
    if (!f) break;
    sizes_ok = sizes_ok && f->size == 640u * 480u * 2u && f->format == ss::PixelFormat::kYUYV;
    if (frames == 0) {
      first_sequence = f->sequence;
      first_ns = f->timestamp_ns;
    } else {
      sequence_ok = sequence_ok && f->sequence > last_sequence;
      time_ok = time_ok && f->timestamp_ns > last_ns;
    }
    last_sequence = f->sequence;
    last_ns = f->timestamp_ns;
    if (frames == 10) {
      left = MeanLuma(*f, 8, 72);  // vivid's default pattern: 75% colour bars, white first (Y 180)
      right = MeanLuma(*f, 568, 632);  // ... black last (Y 16)
    }
  }
  const auto stats = source.stats();
  Check("yuyv_frames", frames == 30 && sizes_ok,
        std::to_string(frames) + " frames of 640x480 YUYV");
  Check("yuyv_sequence",
        sequence_ok && last_sequence - first_sequence + 1 == 30 + stats.frames_dropped,
        "sequence " + std::to_string(first_sequence) + ".." + std::to_string(last_sequence) +
            ", dropped " + std::to_string(stats.frames_dropped));
  Check("yuyv_timestamps", time_ok && last_ns > first_ns,
        "device timestamps " + std::to_string(first_ns) + ".." + std::to_string(last_ns) +
            " ns, mean interval " +
            std::to_string(frames > 1 ? (last_ns - first_ns) / (frames - 1) : 0) + " ns");
  Check("yuyv_colour_bars", left > 160 && right < 40,
        "mean luma left " + std::to_string(left) + " right " + std::to_string(right));
}

void StreamFormat(const std::string& name, ss::PixelFormat format) {
  ss::V4l2Options o;
  o.pixel_format = format;
  o.width = 640;
  o.height = 480;
  try {
    ss::V4l2Source source(o);
    int frames = 0;
    bool sizes_ok = true;
    for (; frames < 3; ++frames) {
      auto f = source.Next();
      if (!f) break;
      sizes_ok = sizes_ok && f->format == format && f->size == ss::FrameBytes(format, 640, 480);
    }
    Check(name, frames == 3 && sizes_ok,
          std::to_string(frames) + " frames of " + ss::PixelFormatName(format));
  } catch (const std::exception& e) {
    Check(name, false, e.what());
  }
}

}  // namespace

int main() {
  const auto devices = ss::ListV4l2Devices();
  std::string listed;
  bool vivid = false;
  for (const auto& d : devices) {
    listed += d.path + " (" + d.driver + ", " + d.card + ") ";
    vivid = vivid || (d.path == "/dev/video0" && d.driver == "vivid");
  }
  Check("list_devices", vivid, listed);
  try {
    StreamYuyv();
  } catch (const std::exception& e) {
    Check("yuyv_frames", false, e.what());
  }
  StreamFormat("nv12_frames", ss::PixelFormat::kNV12);
  StreamFormat("grey_frames", ss::PixelFormat::kMono8);
  StreamFormat("rgb24_frames", ss::PixelFormat::kRGB8);
  StreamFormat("bgr24_frames", ss::PixelFormat::kBGR8);

  ss::V4l2Options o;
  o.pixel_format = ss::PixelFormat::kMJPEG;
  ExpectError<ss::InputError>("unsupported_format", o, "does not offer mjpeg");
  o = {};
  o.pixel_format = ss::PixelFormat::kYUYV;
  o.width = 1000;
  o.height = 1000;
  ExpectError<ss::InputError>("unsupported_size", o, "width/height");
  o = {};
  o.exposure_us = 10000;
  ExpectError<ss::InputError>("missing_exposure_control", o, "exposure_us");
  o = {};
  o.device = "/dev/video9";
  ExpectError<ss::WorkError>("missing_device", o, "no such device");
  o = {};
  o.device = "/dev/null";
  ExpectError<ss::InputError>("not_v4l2", o, "not a V4L2 device");

  std::printf("PROBE_DONE failures=%d\n", failures);
  std::fflush(stdout);
  return failures == 0 ? 0 : 1;
}
