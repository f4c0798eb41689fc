// Runs inside the qemu guest (uvc_test.cc builds the initramfs), while
// uvc_gadget.cc serves a UVC camera on dummy_hcd: drives the libcamera backend
// through libcamera's UVC pipeline handler and the kernel's uvcvideo driver,
// and prints one "CHECK <name> ok|FAIL <detail>" line per check, a
// "MEASURE <name> <value>" line per figure, then "PROBE_DONE".
// Dynamically linked (there is no static libcamera): the test copies the
// shared libraries `ldd` names into the guest.
#include <time.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <exception>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "capture/libcamera/libcamera_source.h"
#include "core/error.h"

namespace {

using ss::LibcameraOptions;
using ss::LibcameraSource;
using ss::PixelFormat;

int failures = 0;

void Check(const std::string& name, bool ok, const std::string& detail) {
  std::printf("CHECK %s %s %s\n", name.c_str(), ok ? "ok" : "FAIL", detail.c_str());
  std::fflush(stdout);
  if (!ok) ++failures;
}

void Measure(const std::string& name, double value) {
  std::printf("MEASURE %s %.3f\n", name.c_str(), value);
  std::fflush(stdout);
}

bool Contains(const std::string& s, const std::string& part) {
  return s.find(part) != std::string::npos;
}

int64_t NowNs() {
  timespec t{};
  clock_gettime(CLOCK_MONOTONIC, &t);
  return t.tv_sec * 1'000'000'000LL + t.tv_nsec;
}

std::string camera_id;  // the gadget's, as libcamera names it

// The frame number the gadget wrote into the first 32 luma samples.
uint32_t EmbeddedNumber(const ss::Frame& f) {
  const int step = f.format == PixelFormat::kYUYV ? 2 : 1;
  uint32_t n = 0;
  for (int bit = 0; bit < 32; ++bit) n = (n << 1) | (f.data[bit * step] > 128 ? 1u : 0u);
  return n;
}

// Luma at the centre of each of the 8 colour bars, on row `y`.
bool BarsMatch(const ss::Frame& f, std::string* detail) {
  static const int kBarLuma[8] = {180, 162, 131, 112, 84, 65, 35, 16};
  const int y = f.height / 2;
  std::ostringstream s;
  bool ok = true;
  for (int b = 0; b < 8; ++b) {
    const int x = (2 * b + 1) * f.width / 16;
    const int luma = f.format == PixelFormat::kYUYV
                         ? f.data[(static_cast<size_t>(y) * f.width + x) * 2]
                         : f.data[static_cast<size_t>(y) * f.width + x];
    s << luma << (b < 7 ? "," : "");
    ok = ok && std::abs(luma - kBarLuma[b]) <= 2;
  }
  *detail = "bar luma " + s.str();
  return ok;
}

struct Run {
  int frames = 0;
  ss::Frame last;  // the others are given back at once
  double seconds = 0;
};

// Collects `count` frames (or what arrives within `timeout_s`), calling `each` on every one.
template <typename Each>
Run Collect(LibcameraSource& source, int count, double timeout_s, Each each) {
  Run run;
  const int64_t start = NowNs();
  int64_t first = 0;
  while (run.frames < count && (NowNs() - start) < timeout_s * 1e9) {
    auto f = source.Next();
    if (!f) break;
    if (run.frames == 0) first = NowNs();
    ++run.frames;
    each(*f);
    run.last = *f;
  }
  run.seconds = first > 0 ? (NowNs() - first) / 1e9 : 0;
  return run;
}

void Streams() {
  LibcameraOptions o;
  o.camera_id = camera_id;
  o.pixel_format = PixelFormat::kYUYV;
  o.width = 320;
  o.height = 240;
  o.exposure_us = 8000;
  o.analogue_gain = 2.0;
  o.white_balance = ss::LibcameraWhiteBalance::kManual;
  o.red_gain = 1.5;
  o.blue_gain = 1.5;
  o.buffers = 4;
  const int64_t opened_ns = NowNs();
  LibcameraSource source(o);
  std::string listed;
  for (const auto& c : source.listed_controls()) listed += c + " ";
  Check("controls_listed", Contains(listed, "ExposureTime") && Contains(listed, "AeEnable"),
        listed);
  std::string ignored;
  for (const auto& c : source.ignored_controls()) ignored += c + "; ";
  Check("controls_ignored",
        Contains(ignored, "ColourGains (white_balance)") && Contains(ignored, "AwbEnable"),
        ignored);
  const auto& cam = source.cameras().at(0);
  Check("yuyv_format", cam.width == 320 && cam.height == 240 && cam.format == PixelFormat::kYUYV,
        std::to_string(cam.width) + "x" + std::to_string(cam.height) + " " +
            ss::PixelFormatName(cam.format));

  // A second open of the same camera while this one streams.
  try {
    LibcameraSource second(o);
    Check("busy_camera", false, "opened twice");
  } catch (const ss::WorkError& e) {
    Check("busy_camera", Contains(e.what(), "busy") && Contains(e.what(), camera_id), e.what());
  }

  // 90 frames: sequence numbers against the numbers the gadget wrote.
  std::vector<uint64_t> sequences, numbers;
  std::vector<int64_t> stamps;
  int sizes_ok = 0, total = 0;
  std::string bars_detail;
  bool bars = false;
  const int64_t first_ns = NowNs();
  int64_t last_ns = first_ns;
  while (total < 90 && NowNs() - first_ns < 40e9) {
    auto f = source.Next();
    if (!f) break;
    ++total;
    last_ns = NowNs();
    sizes_ok += f->width == 320 && f->height == 240 && f->size == 320u * 240u * 2u ? 1 : 0;
    sequences.push_back(f->sequence);
    numbers.push_back(EmbeddedNumber(*f));
    stamps.push_back(f->timestamp_ns);
    if (total == 45) bars = BarsMatch(*f, &bars_detail);
  }
  const auto stats = source.stats();
  Check("yuyv_frames", total == 90 && sizes_ok == total,
        std::to_string(total) + " frames, " + std::to_string(sizes_ok) +
            " of 320x240 YUYV; errors " + std::to_string(stats.errors) + " " + stats.last_error);
  Measure("yuyv_320x240_fps", total > 1 ? (total - 1) / ((last_ns - first_ns) / 1e9) : 0);
  // Skip the first frame after the stream starts: it may hold what was in flight before.
  int mismatched = 0;
  uint64_t gaps = 0;
  for (size_t i = 2; i < sequences.size(); ++i) {
    if (sequences[i] <= sequences[i - 1]) ++mismatched;
    if (sequences[i] - sequences[i - 1] != numbers[i] - numbers[i - 1]) ++mismatched;
    gaps += sequences[i] - sequences[i - 1] - 1;
  }
  Check("yuyv_sequence", mismatched == 0 && sequences.size() > 2,
        "sequence steps match the gadget's frame numbers; gaps " + std::to_string(gaps) +
            ", frames_dropped " + std::to_string(stats.frames_dropped));
  bool increasing = true;
  for (size_t i = 1; i < stamps.size(); ++i) increasing = increasing && stamps[i] > stamps[i - 1];
  const bool in_range = !stamps.empty() && stamps.front() >= opened_ns && stamps.back() <= NowNs();
  Check("yuyv_timestamps", increasing && in_range,
        "CLOCK_MONOTONIC, increasing; first " +
            std::to_string(stamps.empty() ? 0 : stamps.front() - opened_ns) + " ns after open");
  Check("yuyv_colour_bars", bars, bars_detail);

  // Stop() from another thread ends a blocked Next().
  std::thread stopper([&source] {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    source.Stop();
  });
  int after = 0;
  while (source.Next() && after < 1000) ++after;
  stopper.join();
  Check("stop", !source.Next().has_value(), "Next() returns nothing after Stop()");
}

void SmallSize() {
  LibcameraOptions o;
  o.camera_id = camera_id;
  o.pixel_format = PixelFormat::kYUYV;
  o.width = 160;
  o.height = 120;
  LibcameraSource source(o);
  Run run = Collect(source, 20, 20, [](const ss::Frame&) {});
  std::string bars;
  const bool ok = run.frames >= 3 && run.last.width == 160 && run.last.height == 120 &&
                  BarsMatch(run.last, &bars);
  Check("yuyv_160x120", ok, std::to_string(run.frames) + " frames; " + bars);
}

void Nv12() {
  LibcameraOptions o;
  o.camera_id = camera_id;
  o.pixel_format = PixelFormat::kNV12;
  LibcameraSource source(o);
  Run run = Collect(source, 30, 20, [](const ss::Frame&) {});
  std::string bars;
  bool ok = run.frames >= 3;
  if (ok) {
    const auto& f = run.last;
    ok = f.format == PixelFormat::kNV12 && f.width == 320 && f.height == 240 &&
         f.size == 320u * 240u * 3u / 2u && BarsMatch(f, &bars);
    // Chroma of the second bar (U 44, V 142), interleaved after the luma plane.
    const uint8_t* uv = f.data + 320 * 240 + 60 * 320 + 60;
    ok = ok && std::abs(uv[0] - 44) <= 2 && std::abs(uv[1] - 142) <= 2;
    bars += " uv " + std::to_string(uv[0]) + "," + std::to_string(uv[1]);
  }
  Measure("nv12_320x240_fps", run.frames > 1 ? (run.frames - 1) / run.seconds : 0);
  Check("nv12_frames", ok, std::to_string(run.frames) + " frames; " + bars);
}

void Mjpeg() {
  std::ifstream in("/frame.jpg", std::ios::binary);
  std::string jpeg((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  LibcameraOptions o;
  o.camera_id = camera_id;
  o.pixel_format = PixelFormat::kMJPEG;
  LibcameraSource source(o);
  int exact = 0;
  Run run = Collect(source, 30, 20, [&](const ss::Frame& f) {
    // SOI, COM segment with the frame number (8 bytes), then the JPEG after its SOI.
    exact += f.format == PixelFormat::kMJPEG && f.size == jpeg.size() + 8 && f.data[0] == 0xff &&
                     f.data[1] == 0xd8 && f.data[2] == 0xff && f.data[3] == 0xfe &&
                     std::memcmp(f.data + 10, jpeg.data() + 2, jpeg.size() - 2) == 0
                 ? 1
                 : 0;
  });
  Measure("mjpeg_320x240_fps", run.frames > 1 ? (run.frames - 1) / run.seconds : 0);
  // The first frame after a start may be what was in flight from the previous stream.
  Check("mjpeg_frames", run.frames >= 3 && exact >= run.frames - 1,
        std::to_string(exact) + " of " + std::to_string(run.frames) + " byte-exact JPEG frames");
}

template <typename E>
void ExpectError(const std::string& name, const LibcameraOptions& o,
                 const std::vector<std::string>& parts) {
  try {
    LibcameraSource source(o);
    Check(name, false, "no error");
  } catch (const E& e) {
    bool ok = true;
    for (const auto& p : parts) ok = ok && Contains(e.what(), p);
    Check(name, ok, e.what());
  } catch (const std::exception& e) {
    Check(name, false, std::string("wrong error kind: ") + e.what());
  }
}

}  // namespace

// No argument: the main layout (YUYV in two sizes, MJPEG). "nv12": the NV12 layout.
int main(int argc, char** argv) {
  const bool nv12 = argc > 1 && std::string(argv[1]) == "nv12";
  try {
    const auto cameras = ss::ListLibcameraCameras();
    std::string detail;
    for (const auto& c : cameras) {
      detail += c.id + " (" + c.model + ";";
      for (auto f : c.formats) detail += " " + ss::PixelFormatName(f);
      detail += ") ";
    }
    Check(nv12 ? "nv12_list_cameras" : "list_cameras",
          cameras.size() == 1 && cameras[0].formats.size() == 2, detail);
    if (cameras.empty()) {
      std::printf("PROBE_DONE\n");
      return 1;
    }
    camera_id = cameras[0].id;
    if (nv12) {
      Nv12();
    } else {
      LibcameraOptions o;
      o.camera_id = "no-such-camera";
      ExpectError<ss::WorkError>("unknown_camera", o, {"no-such-camera", camera_id});
      o.camera_id = camera_id;
      o.pixel_format = PixelFormat::kRGB8;
      ExpectError<ss::InputError>("unsupported_format", o,
                                  {"pixel_format", "does not offer rgb8", "YUYV"});
      o.pixel_format = PixelFormat::kYUYV;
      o.width = 640;
      o.height = 480;
      ExpectError<ss::InputError>("unsupported_size", o, {"width/height", "640x480", "320x240"});
      o.width = o.height = 0;
      o.exposure_us = 900000;  // above the camera's 500 ms
      ExpectError<ss::InputError>("exposure_out_of_range", o,
                                  {"exposure_us", "outside the camera's range"});

      Streams();
      SmallSize();
      Mjpeg();
    }
  } catch (const std::exception& e) {
    Check(nv12 ? "nv12_probe" : "probe", false, std::string("unexpected error: ") + e.what());
  }
  std::printf("PROBE_DONE%s failures=%d\n", nv12 ? "_NV12" : "", failures);
  std::fflush(stdout);
  return failures == 0 ? 0 : 1;
}
