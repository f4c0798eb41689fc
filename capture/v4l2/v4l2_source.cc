#include "capture/v4l2/v4l2_source.h"

#include <fcntl.h>
#include <linux/videodev2.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <mutex>

#include "core/error.h"
#include "core/log.h"
#include "core/option_checks.h"
#include "core/posix.h"

namespace ss {
namespace {

constexpr int kPollSliceMs = 100;  // Next() checks for Stop() this often

int Xioctl(int fd, unsigned long request, void* arg) {
  int r = 0;
  do {
    r = ioctl(fd, request, arg);
  } while (r == -1 && errno == EINTR);
  return r;
}

struct V4l2Format {
  PixelFormat format;
  uint32_t fourcc;
};

constexpr V4l2Format kV4l2Formats[] = {
    {PixelFormat::kYUYV, V4L2_PIX_FMT_YUYV},       {PixelFormat::kNV12, V4L2_PIX_FMT_NV12},
    {PixelFormat::kMJPEG, V4L2_PIX_FMT_MJPEG},     {PixelFormat::kMJPEG, V4L2_PIX_FMT_JPEG},
    {PixelFormat::kRGB8, V4L2_PIX_FMT_RGB24},      {PixelFormat::kBGR8, V4L2_PIX_FMT_BGR24},
    {PixelFormat::kMono8, V4L2_PIX_FMT_GREY},      {PixelFormat::kBayerRG8, V4L2_PIX_FMT_SRGGB8},
    {PixelFormat::kBayerGR8, V4L2_PIX_FMT_SGRBG8}, {PixelFormat::kBayerGB8, V4L2_PIX_FMT_SGBRG8},
    {PixelFormat::kBayerBG8, V4L2_PIX_FMT_SBGGR8},
};

std::optional<PixelFormat> FromFourcc(uint32_t fourcc) {
  for (const auto& e : kV4l2Formats) {
    if (e.fourcc == fourcc) return e.format;
  }
  return std::nullopt;
}

uint32_t ToFourcc(PixelFormat format) {
  for (const auto& e : kV4l2Formats) {
    if (e.format == format) return e.fourcc;
  }
  return 0;
}

std::string FourccName(uint32_t fourcc) {
  std::string s;
  for (int i = 0; i < 4; ++i) {
    const char c = static_cast<char>((fourcc >> (8 * i)) & 0xff);
    if (c != ' ') s += c;
  }
  return s;
}

std::string Errno() { return ErrnoText(errno); }

// The open file and the mmap'ed buffers, kept alive by the source and by every
// lent frame; a frame's buffer is queued back to the driver when it dies.
struct Device {
  struct Mapping {
    void* start = MAP_FAILED;
    size_t length = 0;
  };
  std::string path;
  int fd = -1;
  std::vector<Mapping> maps;
  std::atomic<bool> streaming{false};

  ~Device() {
    StreamOff();
    for (auto& m : maps) {
      if (m.start != MAP_FAILED) munmap(m.start, m.length);
    }
    if (fd >= 0) close(fd);
  }
  void StreamOff() {
    if (!streaming.exchange(false)) return;
    v4l2_buf_type type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    Xioctl(fd, VIDIOC_STREAMOFF, &type);
  }
  void Queue(uint32_t index) {
    v4l2_buffer b{};
    b.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    b.memory = V4L2_MEMORY_MMAP;
    b.index = index;
    if (Xioctl(fd, VIDIOC_QBUF, &b) < 0 && streaming.load()) {
      Log("capture.v4l2")->warn("{}: cannot queue buffer {} back: {}", path, index, Errno());
    }
  }
};

int OpenDevice(const std::string& path) {
  const int fd = open(path.c_str(), O_RDWR | O_NONBLOCK | O_CLOEXEC);
  if (fd >= 0) return fd;
  if (errno == ENOENT || errno == ENXIO || errno == ENODEV) {
    throw WorkError(
        path,
        "no such device (is the camera plugged in? `spritestation cameras` lists what is present)");
  }
  if (errno == EACCES)
    throw WorkError(path, "permission denied (add the user to the 'video' group)");
  if (errno == EBUSY) throw WorkError(path, "busy: another program holds the device");
  throw WorkError(path, "cannot open: " + Errno());
}

std::vector<uint32_t> OfferedFourccs(int fd) {
  std::vector<uint32_t> out;
  for (uint32_t i = 0;; ++i) {
    v4l2_fmtdesc d{};
    d.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    d.index = i;
    if (Xioctl(fd, VIDIOC_ENUM_FMT, &d) < 0) break;
    out.push_back(d.pixelformat);
  }
  return out;
}

uint32_t CaptureCaps(const v4l2_capability& cap) {
  return (cap.capabilities & V4L2_CAP_DEVICE_CAPS) != 0 ? cap.device_caps : cap.capabilities;
}

}  // namespace

std::vector<V4l2DeviceInfo> ListV4l2Devices() {
  std::vector<std::string> paths;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator("/dev", ec)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind("video", 0) == 0) paths.push_back(entry.path().string());
  }
  std::sort(paths.begin(), paths.end());
  std::vector<V4l2DeviceInfo> out;
  for (const auto& path : paths) {
    const int fd = open(path.c_str(), O_RDWR | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) continue;
    v4l2_capability cap{};
    if (Xioctl(fd, VIDIOC_QUERYCAP, &cap) == 0 &&
        (CaptureCaps(cap) & V4L2_CAP_VIDEO_CAPTURE) != 0) {
      V4l2DeviceInfo d;
      d.path = path;
      d.driver = reinterpret_cast<const char*>(cap.driver);
      d.card = reinterpret_cast<const char*>(cap.card);
      d.bus = reinterpret_cast<const char*>(cap.bus_info);
      for (uint32_t fourcc : OfferedFourccs(fd)) {
        const auto f = FromFourcc(fourcc);
        if (f && std::find(d.formats.begin(), d.formats.end(), *f) == d.formats.end())
          d.formats.push_back(*f);
      }
      out.push_back(d);
    }
    close(fd);
  }
  return out;
}

struct V4l2Source::Impl {
  V4l2Options options;
  std::shared_ptr<Device> device;
  std::vector<SourceCamera> cameras;
  PixelFormat format = PixelFormat::kYUYV;
  int width = 0;
  int height = 0;
  size_t stride = 0;         // bytesperline reported by the driver
  size_t packed_stride = 0;  // what a Frame expects (0 for MJPEG)
  std::atomic<bool> stopped{false};

  mutable std::mutex mutex;  // guards the counters
  SourceStats totals;
  bool have_sequence = false;
  uint64_t last_sequence = 0;
  int waited_ms = 0;

  const std::string& path() const { return options.device; }

  std::optional<v4l2_queryctrl> Query(uint32_t id) const {
    v4l2_queryctrl q{};
    q.id = id;
    if (Xioctl(device->fd, VIDIOC_QUERYCTRL, &q) < 0 || (q.flags & V4L2_CTRL_FLAG_DISABLED) != 0)
      return std::nullopt;
    return q;
  }

  // Sets a control and checks that it holds; InputError naming `field` otherwise.
  void SetControl(uint32_t id, int32_t value, const std::string& field, const std::string& what) {
    const auto q = Query(id);
    if (!q) throw InputError(field, path() + " has no " + what + " control");
    if (value < q->minimum || value > q->maximum) {
      throw InputError(field, path() + ": " + what + " " + std::to_string(value) +
                                  " is outside the device's range " + std::to_string(q->minimum) +
                                  ".." + std::to_string(q->maximum));
    }
    v4l2_control c{};
    c.id = id;
    c.value = value;
    if (Xioctl(device->fd, VIDIOC_S_CTRL, &c) < 0) {
      throw InputError(
          field, path() + " refuses " + what + " = " + std::to_string(value) + ": " + Errno());
    }
    v4l2_control back{};
    back.id = id;
    if (Xioctl(device->fd, VIDIOC_G_CTRL, &back) == 0 && back.value != value) {
      throw InputError(field, path() + ": " + what + " set to " + std::to_string(value) +
                                  " reads back as " + std::to_string(back.value));
    }
  }

  // Presses a button control (an action such as a one-time white balance).
  void Trigger(uint32_t id, const std::string& field, const std::string& what) {
    if (!Query(id))
      throw InputError(field, path() + " cannot do " + what + " (it has no such control)");
    v4l2_control c{};
    c.id = id;
    c.value = 1;
    if (Xioctl(device->fd, VIDIOC_S_CTRL, &c) < 0)
      throw InputError(field, path() + " refuses " + what + ": " + Errno());
  }

  // Turns an automatic mode off when the device has it.
  void ManualIfPresent(uint32_t id, int32_t manual_value, const std::string& field,
                       const std::string& what) {
    if (Query(id)) SetControl(id, manual_value, field, what);
  }

  void Problem(const std::string& message) {
    Log("capture.v4l2")->warn("{}", message);
    ++totals.errors;
    totals.last_error = message;
  }
};

bool V4l2Options::IsValid(std::string* why) const {
  OptionProblems check(why);
  check(!device.empty(), "device", "expected a device path such as /dev/video0");
  check(width >= 0 && height >= 0 && (width > 0) == (height > 0), "width/height",
        "give both or neither (got " + std::to_string(width) + "x" + std::to_string(height) + ")");
  check.Within(fps, AtLeast(0), "fps", "0 (the driver's) or frames per second");
  check.Within(exposure_us, AtLeast(0), "exposure_us", "0 (auto) or microseconds");
  check.Within(gain, AtLeast(-1), "gain", "-1 (auto) or a gain >= 0");
  check.Within(white_balance_k, AtLeast(0), "white_balance_k", "0 (auto) or kelvin");
  check.Within(buffers, AtLeast(2), "buffers", "2 or more");
  check.Within(frame_timeout_ms, AtLeast(1), "frame_timeout_ms", "at least 1 ms");
  return check.ok();
}

V4l2Source::V4l2Source(V4l2Options options) : impl_(std::make_unique<Impl>()) {
  Impl& s = *impl_;
  s.options = options;
  if (std::string why; !options.IsValid(&why)) throw InputError("v4l2 options", why);
  auto device = std::make_shared<Device>();
  device->path = options.device;
  device->fd = OpenDevice(options.device);
  s.device = device;
  const int fd = device->fd;
  const std::string& path = options.device;

  v4l2_capability cap{};
  if (Xioctl(fd, VIDIOC_QUERYCAP, &cap) < 0)
    throw InputError(path, "not a V4L2 device (" + Errno() + ")");
  const uint32_t caps = CaptureCaps(cap);
  if ((caps & V4L2_CAP_VIDEO_CAPTURE) == 0) {
    throw InputError(path, (caps & V4L2_CAP_VIDEO_CAPTURE_MPLANE) != 0
                               ? "offers only multi-planar capture, which is not supported"
                               : "is not a video capture device (an output or metadata node?)");
  }
  if ((caps & V4L2_CAP_STREAMING) == 0) throw InputError(path, "does not support streaming I/O");

  // Format and size.
  v4l2_format fmt{};
  fmt.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  if (Xioctl(fd, VIDIOC_G_FMT, &fmt) < 0)
    throw WorkError(path, "cannot read the format: " + Errno());
  const std::vector<uint32_t> offered = OfferedFourccs(fd);
  std::string offered_names;
  for (uint32_t f : offered) offered_names += (offered_names.empty() ? "" : ", ") + FourccName(f);
  uint32_t want = fmt.fmt.pix.pixelformat;
  if (options.pixel_format) {
    want = ToFourcc(*options.pixel_format);
    if (*options.pixel_format == PixelFormat::kMJPEG &&
        std::find(offered.begin(), offered.end(), want) == offered.end() &&
        std::find(offered.begin(), offered.end(), V4L2_PIX_FMT_JPEG) != offered.end()) {
      want = V4L2_PIX_FMT_JPEG;
    }
    if (want == 0 || std::find(offered.begin(), offered.end(), want) == offered.end()) {
      throw InputError("pixel_format", path + " does not offer " +
                                           PixelFormatName(*options.pixel_format) +
                                           " (it offers: " + offered_names + ")");
    }
  }
  const uint32_t want_w =
      options.width > 0 ? static_cast<uint32_t>(options.width) : fmt.fmt.pix.width;
  const uint32_t want_h =
      options.height > 0 ? static_cast<uint32_t>(options.height) : fmt.fmt.pix.height;
  fmt.fmt.pix.pixelformat = want;
  fmt.fmt.pix.width = want_w;
  fmt.fmt.pix.height = want_h;
  fmt.fmt.pix.field = V4L2_FIELD_NONE;
  fmt.fmt.pix.bytesperline = 0;
  if (Xioctl(fd, VIDIOC_S_FMT, &fmt) < 0) {
    if (errno == EBUSY) throw WorkError(path, "busy: another program is streaming from it");
    throw WorkError(path, "cannot set the format " + FourccName(want) + ": " + Errno());
  }
  const auto format = FromFourcc(fmt.fmt.pix.pixelformat);
  if (!format) {
    throw InputError("pixel_format",
                     path + " switched to " + FourccName(fmt.fmt.pix.pixelformat) +
                         ", which SpriteStation does not read (it offers: " + offered_names + ")");
  }
  if (fmt.fmt.pix.pixelformat != want) {
    throw InputError("pixel_format", path + " does not take " + FourccName(want) +
                                         " (it offers: " + offered_names + ")");
  }
  if (fmt.fmt.pix.width != want_w || fmt.fmt.pix.height != want_h) {
    throw InputError("width/height", path + " cannot capture " + FourccName(want) + " at " +
                                         std::to_string(want_w) + "x" + std::to_string(want_h) +
                                         " (nearest: " + std::to_string(fmt.fmt.pix.width) + "x" +
                                         std::to_string(fmt.fmt.pix.height) + ")");
  }
  s.format = *format;
  s.width = static_cast<int>(fmt.fmt.pix.width);
  s.height = static_cast<int>(fmt.fmt.pix.height);
  s.stride = fmt.fmt.pix.bytesperline;
  s.packed_stride = s.format == PixelFormat::kMJPEG ? 0 : FrameBytes(s.format, s.width, 1);
  if (s.format == PixelFormat::kNV12) s.packed_stride = static_cast<size_t>(s.width);

  // Frame rate.
  double fps = 0.0;
  v4l2_streamparm parm{};
  parm.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  if (options.fps > 0) {
    if (Xioctl(fd, VIDIOC_G_PARM, &parm) < 0 ||
        (parm.parm.capture.capability & V4L2_CAP_TIMEPERFRAME) == 0) {
      throw InputError("fps", path + " does not let the frame rate be set");
    }
    parm.parm.capture.timeperframe.numerator = 1000;
    parm.parm.capture.timeperframe.denominator =
        static_cast<uint32_t>(std::lround(options.fps * 1000));
    if (Xioctl(fd, VIDIOC_S_PARM, &parm) < 0)
      throw InputError("fps", path + " refuses the frame rate: " + Errno());
  }
  if (Xioctl(fd, VIDIOC_G_PARM, &parm) == 0 && parm.parm.capture.timeperframe.numerator > 0) {
    fps = static_cast<double>(parm.parm.capture.timeperframe.denominator) /
          parm.parm.capture.timeperframe.numerator;
  }

  // Exposure, gain and white balance: automatic modes off, values set and read back.
  if (options.exposure_us > 0) {
    s.ManualIfPresent(V4L2_CID_EXPOSURE_AUTO, V4L2_EXPOSURE_MANUAL, "exposure_us", "auto exposure");
    s.SetControl(V4L2_CID_EXPOSURE_ABSOLUTE,
                 static_cast<int32_t>(std::lround(options.exposure_us / 100.0)), "exposure_us",
                 "exposure (100 us units)");
  }
  if (options.gain >= 0) {
    s.ManualIfPresent(V4L2_CID_AUTOGAIN, 0, "gain", "auto gain");
    s.SetControl(V4L2_CID_GAIN, options.gain, "gain", "gain");
  }
  if (options.white_balance_k > 0) {
    s.ManualIfPresent(V4L2_CID_AUTO_WHITE_BALANCE, 0, "white_balance_k", "auto white balance");
    s.SetControl(V4L2_CID_WHITE_BALANCE_TEMPERATURE, options.white_balance_k, "white_balance_k",
                 "white balance temperature");
  } else if (options.white_balance_once) {
    s.ManualIfPresent(V4L2_CID_AUTO_WHITE_BALANCE, 0, "white_balance", "auto white balance");
    s.Trigger(V4L2_CID_DO_WHITE_BALANCE, "white_balance", "a one-time white balance");
  }

  // Buffers.
  v4l2_requestbuffers req{};
  req.count = static_cast<uint32_t>(options.buffers);
  req.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  req.memory = V4L2_MEMORY_MMAP;
  if (Xioctl(fd, VIDIOC_REQBUFS, &req) < 0) {
    if (errno == EBUSY) throw WorkError(path, "busy: another program is streaming from it");
    throw WorkError(path, "cannot get streaming buffers: " + Errno());
  }
  if (req.count < 2)
    throw WorkError(path, "the driver gave " + std::to_string(req.count) + " buffer(s); need 2");
  for (uint32_t i = 0; i < req.count; ++i) {
    v4l2_buffer b{};
    b.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    b.memory = V4L2_MEMORY_MMAP;
    b.index = i;
    if (Xioctl(fd, VIDIOC_QUERYBUF, &b) < 0)
      throw WorkError(path, "cannot query buffer: " + Errno());
    Device::Mapping m;
    m.length = b.length;
    m.start = mmap(nullptr, b.length, PROT_READ | PROT_WRITE, MAP_SHARED, fd, b.m.offset);
    if (m.start == MAP_FAILED) throw WorkError(path, "cannot map buffer: " + Errno());
    device->maps.push_back(m);
  }
  for (uint32_t i = 0; i < req.count; ++i) {
    v4l2_buffer b{};
    b.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    b.memory = V4L2_MEMORY_MMAP;
    b.index = i;
    if (Xioctl(fd, VIDIOC_QBUF, &b) < 0) throw WorkError(path, "cannot queue buffer: " + Errno());
  }
  v4l2_buf_type type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  if (Xioctl(fd, VIDIOC_STREAMON, &type) < 0) {
    if (errno == EBUSY) throw WorkError(path, "busy: another program is streaming from it");
    throw WorkError(path, "cannot start streaming: " + Errno());
  }
  device->streaming.store(true);

  SourceCamera sc;
  sc.name = options.name.empty() ? path : options.name;
  sc.width = s.width;
  sc.height = s.height;
  sc.format = s.format;
  sc.fps = fps;
  s.cameras.push_back(sc);
  Log("capture.v4l2")
      ->info("{}: {} ({}) streaming {} {}x{} at {:.2f} frames/s, {} buffers", path,
             reinterpret_cast<const char*>(cap.card), reinterpret_cast<const char*>(cap.driver),
             FourccName(fmt.fmt.pix.pixelformat), s.width, s.height, fps, req.count);
}

V4l2Source::~V4l2Source() {
  Stop();
  if (impl_->device) impl_->device->StreamOff();
}

const std::vector<SourceCamera>& V4l2Source::cameras() const { return impl_->cameras; }

std::optional<Frame> V4l2Source::Next() {
  Impl& s = *impl_;
  const int fd = s.device->fd;
  while (!s.stopped.load()) {
    pollfd p{};
    p.fd = fd;
    p.events = POLLIN;
    const int r = poll(&p, 1, kPollSliceMs);
    if (r < 0) {
      if (errno == EINTR) continue;
      throw WorkError(s.path(), "poll failed: " + Errno());
    }
    if (r == 0) {
      std::lock_guard<std::mutex> lock(s.mutex);
      s.waited_ms += kPollSliceMs;
      if (s.waited_ms >= s.options.frame_timeout_ms) {
        s.Problem(s.path() + ": no frame for " + std::to_string(s.waited_ms) + " ms");
        s.waited_ms = 0;
      }
      continue;
    }
    v4l2_buffer b{};
    b.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    b.memory = V4L2_MEMORY_MMAP;
    if (Xioctl(fd, VIDIOC_DQBUF, &b) < 0) {
      if (errno == EAGAIN) continue;
      throw WorkError(s.path(), "the device failed or disappeared while streaming: " + Errno());
    }
    std::unique_lock<std::mutex> lock(s.mutex);
    s.waited_ms = 0;
    const uint64_t sequence = b.sequence;
    if (s.have_sequence && sequence > s.last_sequence + 1)
      s.totals.frames_dropped += sequence - s.last_sequence - 1;
    s.have_sequence = true;
    s.last_sequence = sequence;
    const size_t expected = s.format == PixelFormat::kMJPEG
                                ? 1
                                : s.stride * static_cast<size_t>(s.height) *
                                      (s.format == PixelFormat::kNV12 ? 3 : 2) / 2;
    std::string problem;
    if ((b.flags & V4L2_BUF_FLAG_ERROR) != 0) {
      problem = "the driver flagged it corrupt";
    } else if (b.bytesused < expected && s.format != PixelFormat::kMJPEG) {
      problem = "short frame (" + std::to_string(b.bytesused) + " bytes)";
    } else if (s.format == PixelFormat::kMJPEG && b.bytesused == 0) {
      problem = "empty JPEG";
    }
    if (!problem.empty()) {
      ++s.totals.frames_dropped;
      s.Problem(s.path() + ": frame " + std::to_string(sequence) + ": " + problem);
      lock.unlock();
      s.device->Queue(b.index);
      continue;
    }
    ++s.totals.frames_delivered;
    lock.unlock();

    const auto* data = static_cast<const uint8_t*>(s.device->maps[b.index].start);
    Frame f;
    if (s.format == PixelFormat::kMJPEG) {
      auto device = s.device;
      const uint32_t index = b.index;
      f = Frame::Borrowed(s.format, s.width, s.height, data, b.bytesused,
                          [device, index] { device->Queue(index); });
    } else if (s.stride == s.packed_stride) {
      auto device = s.device;
      const uint32_t index = b.index;
      f = Frame::Borrowed(s.format, s.width, s.height, data,
                          FrameBytes(s.format, s.width, s.height),
                          [device, index] { device->Queue(index); });
    } else {
      // Rows padded by the driver: repack into an owned frame and hand the buffer straight back.
      std::vector<uint8_t> pixels(FrameBytes(s.format, s.width, s.height));
      const size_t rows = pixels.size() / s.packed_stride;
      for (size_t y = 0; y < rows; ++y)
        std::memcpy(&pixels[y * s.packed_stride], data + y * s.stride, s.packed_stride);
      s.device->Queue(b.index);
      f = Frame::Owned(s.format, s.width, s.height, std::move(pixels));
    }
    f.camera = s.options.camera_index;
    f.sequence = sequence;
    f.timestamp_ns = static_cast<int64_t>(b.timestamp.tv_sec) * 1'000'000'000 +
                     static_cast<int64_t>(b.timestamp.tv_usec) * 1000;
    return f;
  }
  return std::nullopt;
}

void V4l2Source::Stop() { impl_->stopped.store(true); }

SourceStats V4l2Source::stats() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->totals;
}

std::optional<int32_t> V4l2Source::control(uint32_t id) const {
  v4l2_control c{};
  c.id = id;
  if (Xioctl(impl_->device->fd, VIDIOC_G_CTRL, &c) < 0) return std::nullopt;
  return c.value;
}

}  // namespace ss
