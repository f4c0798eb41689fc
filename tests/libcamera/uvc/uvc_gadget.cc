// A USB Video Class camera in userspace, for the qemu test of the libcamera
// backend (uvc_test.cc). Runs inside the guest: gadgetfs on dummy_hcd's
// device side presents a UVC 1.0 camera with a bulk streaming endpoint, which
// the guest's own uvcvideo driver enumerates as a webcam and libcamera's UVC
// pipeline handler drives. (dummy_hcd fails every isochronous transfer, and the
// kernel's configfs UVC function is isochronous only in 6.1.)
//
// Formats: YUYV 320x240 and 160x120 and MJPEG 320x240 (the JPEG given as
// argv[1], with the frame number in a COM segment); with argv[2] = "nv12",
// NV12 320x240 and YUYV 320x240. Uncompressed frames are
// colour bars with the frame number in the first 32 luma samples (235 = 1,
// 16 = 0, most significant bit first). Camera terminal controls: auto-exposure
// mode and absolute exposure time; processing unit: gain. Every SET_CUR of a
// control is printed as `GADGET SET entity=E selector=S value=V`.
#include <fcntl.h>
#include <linux/usb/ch9.h>
#include <linux/usb/gadgetfs.h>
#include <linux/usb/video.h>
#include <poll.h>
#include <pthread.h>
#include <sched.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace {

// errno's text, thread-safe (the gadget's threads fail independently); GNU strerror_r.
std::string ErrnoText(int err) {
  char buffer[256];
  return strerror_r(err, buffer, sizeof(buffer));
}

constexpr uint8_t kEndpoint = 0x81;      // dummy_udc's ep1in-bulk
constexpr uint32_t kMaxPayload = 16384;  // dwMaxPayloadTransferSize: 32 high-speed packets
constexpr uint32_t kInterval = 333333;   // 30 frames/s in 100 ns units
constexpr uint8_t kCameraTerminal = 1, kOutputTerminal = 2, kProcessingUnit = 3;

struct FrameSize {
  uint16_t width, height;
};
struct Format {
  enum Kind { kYUYV, kNV12, kMJPEG } kind;
  std::vector<FrameSize> frames;
};
// Two layouts: the host timed out reading a 294-byte configuration descriptor
// from gadgetfs on dummy_hcd (236 bytes work), so NV12 gets its own.
const std::vector<Format> kMainFormats = {
    {Format::kYUYV, {{320, 240}, {160, 120}}},
    {Format::kMJPEG, {{320, 240}}},
};
const std::vector<Format> kNv12Formats = {
    {Format::kNV12, {{320, 240}}},
    {Format::kYUYV, {{320, 240}}},
};
std::vector<Format> kFormats = kMainFormats;

std::string jpeg;  // the MJPEG frame, from argv[1]

uint32_t FrameBytes(const Format& f, FrameSize s) {
  switch (f.kind) {
    case Format::kYUYV:
      return s.width * s.height * 2u;
    case Format::kNV12:
      return s.width * s.height * 3u / 2u;
    case Format::kMJPEG:
      return static_cast<uint32_t>(jpeg.size() + 8);
  }
  return 0;
}

// Little-endian descriptor writer.
struct Bytes {
  std::vector<uint8_t> b;
  Bytes& u8(unsigned v) {
    b.push_back(static_cast<uint8_t>(v));
    return *this;
  }
  Bytes& u16(unsigned v) { return u8(v & 0xff).u8((v >> 8) & 0xff); }
  Bytes& u32(uint32_t v) { return u16(v & 0xffff).u16(v >> 16); }
  Bytes& raw(const uint8_t* p, size_t n) {
    b.insert(b.end(), p, p + n);
    return *this;
  }
  Bytes& add(const Bytes& o) { return raw(o.b.data(), o.b.size()); }
};

const uint8_t kGuidYUY2[16] = {'Y',  'U', 'Y', '2',  0, 0,    0x10, 0,
                               0x80, 0,   0,   0xaa, 0, 0x38, 0x9b, 0x71};
const uint8_t kGuidNV12[16] = {'N',  'V', '1', '2',  0, 0,    0x10, 0,
                               0x80, 0,   0,   0xaa, 0, 0x38, 0x9b, 0x71};

Bytes ConfigDescriptor(unsigned max_packet) {
  // Video control: header, camera terminal, processing unit, output terminal.
  Bytes it, pu, ot;
  it.u8(18)
      .u8(0x24)
      .u8(0x02)
      .u8(kCameraTerminal)
      .u16(0x0201)
      .u8(0)
      .u8(0)
      .u16(0)
      .u16(0)
      .u16(0)
      .u8(3);
  it.u8((1 << 1) | (1 << 3)).u8(0).u8(0);  // bmControls: AE mode, exposure time (absolute)
  pu.u8(11)
      .u8(0x24)
      .u8(0x05)
      .u8(kProcessingUnit)
      .u8(kCameraTerminal)
      .u16(0)
      .u8(2)
      .u16(1 << 9)
      .u8(0);  // gain
  ot.u8(9).u8(0x24).u8(0x03).u8(kOutputTerminal).u16(0x0101).u8(0).u8(kProcessingUnit).u8(0);
  const unsigned vc_total = 13 + it.b.size() + pu.b.size() + ot.b.size();
  Bytes vc;
  vc.u8(13).u8(0x24).u8(0x01).u16(0x0100).u16(vc_total).u32(48000000).u8(1).u8(1);
  vc.add(it).add(pu).add(ot);

  // Video streaming: input header, then each format and its frames.
  Bytes formats;
  for (size_t fi = 0; fi < kFormats.size(); ++fi) {
    const Format& f = kFormats[fi];
    const auto nframes = static_cast<unsigned>(f.frames.size());
    if (f.kind == Format::kMJPEG) {
      formats.u8(11).u8(0x24).u8(0x06).u8(fi + 1).u8(nframes).u8(0x01).u8(1).u8(0).u8(0).u8(0).u8(
          0);
    } else {
      formats.u8(27).u8(0x24).u8(0x04).u8(fi + 1).u8(nframes);
      formats.raw(f.kind == Format::kYUYV ? kGuidYUY2 : kGuidNV12, 16);
      formats.u8(f.kind == Format::kYUYV ? 16 : 12).u8(1).u8(0).u8(0).u8(0).u8(0);
    }
    for (size_t k = 0; k < f.frames.size(); ++k) {
      const FrameSize s = f.frames[k];
      const uint32_t bytes = f.kind == Format::kMJPEG ? s.width * s.height * 2u : FrameBytes(f, s);
      formats.u8(30).u8(0x24).u8(f.kind == Format::kMJPEG ? 0x07 : 0x05).u8(k + 1).u8(0);
      formats.u16(s.width).u16(s.height).u32(bytes * 8 * 30).u32(bytes * 8 * 30).u32(bytes);
      formats.u32(kInterval).u8(1).u32(kInterval);
    }
  }
  const unsigned header = 13 + kFormats.size();  // one bmaControls byte per format
  const unsigned vs_total = header + formats.b.size();
  Bytes vs;
  vs.u8(header)
      .u8(0x24)
      .u8(0x01)
      .u8(kFormats.size())
      .u16(vs_total)
      .u8(kEndpoint)
      .u8(0)
      .u8(kOutputTerminal);
  vs.u8(0).u8(0).u8(0).u8(1);
  for (size_t i = 0; i < kFormats.size(); ++i) vs.u8(0);
  vs.add(formats);

  Bytes body;
  body.u8(8).u8(USB_DT_INTERFACE_ASSOCIATION).u8(0).u8(2).u8(0x0e).u8(0x03).u8(0).u8(2);
  body.u8(9).u8(USB_DT_INTERFACE).u8(0).u8(0).u8(0).u8(0x0e).u8(0x01).u8(0).u8(2).add(vc);
  body.u8(9).u8(USB_DT_INTERFACE).u8(1).u8(0).u8(1).u8(0x0e).u8(0x02).u8(0).u8(0).add(vs);
  body.u8(7).u8(USB_DT_ENDPOINT).u8(kEndpoint).u8(USB_ENDPOINT_XFER_BULK).u16(max_packet).u8(0);
  Bytes config;
  config.u8(9).u8(USB_DT_CONFIG).u16(9 + body.b.size()).u8(2).u8(1).u8(0).u8(0x80).u8(50).add(body);
  return config;
}

Bytes DeviceDescriptor() {
  Bytes d;
  d.u8(18).u8(USB_DT_DEVICE).u16(0x0200).u8(0xef).u8(0x02).u8(0x01).u8(64);
  d.u16(0x1d6b).u16(0x0102).u16(0x0100).u8(1).u8(2).u8(3).u8(1);
  return d;
}

Bytes StringDescriptor(unsigned index) {
  Bytes s;
  if (index == 0) return s.u8(4).u8(USB_DT_STRING).u16(0x0409);
  const char* text = index == 1   ? "SpriteStation"
                     : index == 2 ? "SpriteStation UVC test camera"
                                  : "SS0001";
  s.u8(2 + 2 * std::strlen(text)).u8(USB_DT_STRING);
  for (const char* c = text; *c; ++c) s.u16(static_cast<uint8_t>(*c));
  return s;
}

// One UVC control: its size and the values GET_MIN/MAX/RES/DEF/CUR return.
struct Control {
  uint8_t entity, selector, size;
  int32_t min, max, res, def, cur;
};
std::mutex controls_mutex;
std::vector<Control> controls = {
    {kCameraTerminal, UVC_CT_AE_MODE_CONTROL, 1, 0, 0, 0x09, 0x08,
     0x08},  // manual or aperture priority
    {kCameraTerminal, UVC_CT_EXPOSURE_TIME_ABSOLUTE_CONTROL, 4, 1, 5000, 1, 333,
     333},  // 100 us units
    {kProcessingUnit, UVC_PU_GAIN_CONTROL, 2, 0, 400, 1, 100, 100},
};

// The streaming state the host negotiates.
struct Stream {
  std::mutex mutex;
  uvc_streaming_control probe{};
  uint8_t format = 1, frame = 1;
  unsigned generation = 0;  // commits so far
  unsigned speed = 0;
};
Stream stream;

void FillProbe(uvc_streaming_control* c, unsigned format, unsigned frame) {
  if (format < 1 || format > kFormats.size()) format = 1;
  if (frame < 1 || frame > kFormats[format - 1].frames.size()) frame = 1;
  std::memset(c, 0, sizeof *c);
  c->bFormatIndex = static_cast<uint8_t>(format);
  c->bFrameIndex = static_cast<uint8_t>(frame);
  c->dwFrameInterval = kInterval;
  c->dwMaxVideoFrameSize = FrameBytes(kFormats[format - 1], kFormats[format - 1].frames[frame - 1]);
  c->dwMaxPayloadTransferSize = kMaxPayload;
}

constexpr size_t kProbeSize = 26;  // UVC 1.0

int ep0 = -1;
std::atomic<int> ep{-1};  // the streaming endpoint, enabled at SET_CONFIGURATION

// Enables ep1in-bulk; the host may start reading as soon as it has committed a format.
bool EnableStreamingEndpoint() {
  if (ep.load() >= 0) return true;
  const int fd = open("/dev/gadget/ep1in-bulk", O_RDWR);
  if (fd < 0) {
    std::printf("GADGET cannot open ep1in-bulk: %s\n", ErrnoText(errno).c_str());
    return false;
  }
  Bytes config;
  config.u32(1);
  config.u8(7).u8(USB_DT_ENDPOINT).u8(kEndpoint).u8(USB_ENDPOINT_XFER_BULK).u16(64).u8(0);
  config.u8(7).u8(USB_DT_ENDPOINT).u8(kEndpoint).u8(USB_ENDPOINT_XFER_BULK).u16(512).u8(0);
  if (write(fd, config.b.data(), config.b.size()) < 0) {
    std::printf("GADGET cannot configure ep1in-bulk: %s\n", ErrnoText(errno).c_str());
    close(fd);
    return false;
  }
  std::printf("GADGET streaming endpoint enabled\n");
  ep.store(fd);
  return true;
}

void Stall(const usb_ctrlrequest& r) {
  uint8_t dummy = 0;
  if (r.bRequestType & USB_DIR_IN) {
    (void)!read(ep0, &dummy, 0);
  } else {
    (void)!write(ep0, &dummy, 0);
  }
}

void Reply(const usb_ctrlrequest& r, const void* data, size_t n) {
  const size_t len = n < r.wLength ? n : r.wLength;
  if (write(ep0, data, len) < 0) std::printf("GADGET reply failed: %s\n", ErrnoText(errno).c_str());
}

void Ack() {
  uint8_t dummy = 0;
  (void)!read(ep0, &dummy, 0);
}

void StreamingRequest(const usb_ctrlrequest& r) {
  const unsigned selector = r.wValue >> 8;
  if (selector != UVC_VS_PROBE_CONTROL && selector != UVC_VS_COMMIT_CONTROL) return Stall(r);
  std::unique_lock<std::mutex> lock(stream.mutex);
  uvc_streaming_control c{};
  switch (r.bRequest) {
    case UVC_SET_CUR: {
      uint8_t buf[64] = {};
      lock.unlock();
      const ssize_t n = read(ep0, buf, r.wLength);
      lock.lock();
      if (n < 4) return;
      uvc_streaming_control in{};
      std::memcpy(&in, buf,
                  static_cast<size_t>(n) < sizeof in ? static_cast<size_t>(n) : sizeof in);
      FillProbe(&stream.probe, in.bFormatIndex, in.bFrameIndex);
      if (selector == UVC_VS_COMMIT_CONTROL) {
        stream.format = stream.probe.bFormatIndex;
        stream.frame = stream.probe.bFrameIndex;
        ++stream.generation;
        std::printf("GADGET COMMIT format=%u frame=%u\n", stream.format, stream.frame);
        std::fflush(stdout);
      }
      return;
    }
    case UVC_GET_CUR:
      c = stream.probe;
      break;
    case UVC_GET_MIN:  // one format and one frame size: the least, the most and the default
    case UVC_GET_DEF:
    case UVC_GET_MAX:
      FillProbe(&c, 1, 1);
      break;
    case UVC_GET_LEN: {
      const uint16_t len = kProbeSize;
      lock.unlock();
      return Reply(r, &len, 2);
    }
    case UVC_GET_INFO: {
      const uint8_t info = 0x03;
      lock.unlock();
      return Reply(r, &info, 1);
    }
    default:
      lock.unlock();
      return Stall(r);
  }
  lock.unlock();
  Reply(r, &c, kProbeSize);
}

void ControlRequest(const usb_ctrlrequest& r) {
  const unsigned entity = r.wIndex >> 8, selector = r.wValue >> 8;
  std::lock_guard<std::mutex> lock(controls_mutex);
  Control* ctrl = nullptr;
  for (auto& c : controls) {
    if (c.entity == entity && c.selector == selector) ctrl = &c;
  }
  if (ctrl == nullptr) return Stall(r);
  int32_t value = 0;
  switch (r.bRequest) {
    case UVC_SET_CUR: {
      uint8_t buf[8] = {};
      const ssize_t n = read(ep0, buf, r.wLength);
      if (n < ctrl->size) return;
      int32_t v = 0;
      std::memcpy(&v, buf, ctrl->size);
      ctrl->cur = v;
      std::printf("GADGET SET entity=%u selector=%u value=%d\n", entity, selector, v);
      std::fflush(stdout);
      return;
    }
    case UVC_GET_CUR:
      value = ctrl->cur;
      break;
    case UVC_GET_MIN:
      value = ctrl->min;
      break;
    case UVC_GET_MAX:
      value = ctrl->max;
      break;
    case UVC_GET_RES:
      value = ctrl->res;
      break;
    case UVC_GET_DEF:
      value = ctrl->def;
      break;
    case UVC_GET_LEN: {
      const uint16_t len = ctrl->size;
      return Reply(r, &len, 2);
    }
    case UVC_GET_INFO: {
      const uint8_t info = 0x03;  // GET and SET supported
      return Reply(r, &info, 1);
    }
    default:
      return Stall(r);
  }
  Reply(r, &value, ctrl->size);
}

void Setup(const usb_ctrlrequest& r) {
  const unsigned type = r.bRequestType & USB_TYPE_MASK;
  if (type == USB_TYPE_STANDARD) {
    switch (r.bRequest) {
      case USB_REQ_GET_DESCRIPTOR:
        if ((r.wValue >> 8) == USB_DT_STRING) {
          const Bytes s = StringDescriptor(r.wValue & 0xff);
          return Reply(r, s.b.data(), s.b.size());
        }
        return Stall(r);
      case USB_REQ_SET_CONFIGURATION:
        if (r.wValue != 0) EnableStreamingEndpoint();
        return Ack();
      case USB_REQ_SET_INTERFACE:
        return Ack();
      case USB_REQ_GET_INTERFACE: {
        const uint8_t alt = 0;
        return Reply(r, &alt, 1);
      }
      default:
        return Stall(r);
    }
  }
  if (type == USB_TYPE_CLASS && (r.bRequestType & USB_RECIP_MASK) == USB_RECIP_INTERFACE) {
    if ((r.wIndex & 0xff) == 1) return StreamingRequest(r);
    if ((r.wIndex & 0xff) == 0) return ControlRequest(r);
  }
  Stall(r);
}

// Colour bars (75 %), Y U V.
const uint8_t kBars[8][3] = {{180, 128, 128}, {162, 44, 142}, {131, 156, 44}, {112, 72, 58},
                             {84, 184, 198},  {65, 100, 212}, {35, 212, 114}, {16, 128, 128}};

void FillFrame(const Format& f, FrameSize s, uint32_t number, std::vector<uint8_t>& out) {
  out.assign(FrameBytes(f, s), 0);
  if (f.kind == Format::kMJPEG) {
    // SOI, a COM segment holding the number, then the rest of the JPEG.
    const uint8_t head[] = {0xff,
                            0xd8,
                            0xff,
                            0xfe,
                            0x00,
                            0x06,
                            static_cast<uint8_t>(number >> 24),
                            static_cast<uint8_t>(number >> 16),
                            static_cast<uint8_t>(number >> 8),
                            static_cast<uint8_t>(number)};
    std::memcpy(out.data(), head, sizeof head);
    // The JPEG's bytes (a std::string holds them: memcpy of its size - 2 read to
    // bugprone-not-null-terminated-result as text copied without its terminator).
    std::copy(jpeg.begin() + 2, jpeg.end(), out.begin() + sizeof head);
    return;
  }
  const int w = s.width, h = s.height;
  if (f.kind == Format::kYUYV) {
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; x += 2) {
        const uint8_t* bar = kBars[x * 8 / w];
        uint8_t* p = &out[(static_cast<size_t>(y) * w + x) * 2];
        p[0] = bar[0], p[1] = bar[1], p[2] = bar[0], p[3] = bar[2];
      }
    }
    for (int bit = 0; bit < 32; ++bit) out[bit * 2] = (number >> (31 - bit)) & 1 ? 235 : 16;
  } else {
    uint8_t* luma = out.data();
    uint8_t* chroma = out.data() + static_cast<size_t>(w) * h;
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) luma[y * w + x] = kBars[x * 8 / w][0];
    }
    for (int y = 0; y < h / 2; ++y) {
      for (int x = 0; x < w; x += 2) {
        chroma[y * w + x] = kBars[x * 8 / w][1];
        chroma[y * w + x + 1] = kBars[x * 8 / w][2];
      }
    }
    for (int bit = 0; bit < 32; ++bit) luma[bit] = (number >> (31 - bit)) & 1 ? 235 : 16;
  }
}

int64_t NowNs() {
  timespec t{};
  clock_gettime(CLOCK_MONOTONIC, &t);
  return t.tv_sec * 1'000'000'000LL + t.tv_nsec;
}

// Sends frames once the host has committed a format, paced at 30 frames/s.
void StreamLoop() {
  uint32_t number = 0;
  uint8_t fid = 0;
  unsigned seen_generation = 0;
  std::vector<uint8_t> frame, payload(kMaxPayload);
  int64_t next_ns = 0;
  for (;;) {
    Format format;
    FrameSize size{};
    unsigned generation = 0;
    {
      std::lock_guard<std::mutex> lock(stream.mutex);
      generation = stream.generation;
      format = kFormats[stream.format - 1];
      size = format.frames[stream.frame - 1];
    }
    if (generation == 0 || ep.load() < 0) {
      usleep(10000);
      continue;
    }
    if (generation != seen_generation) {
      seen_generation = generation;
      fid ^= 1;  // whatever was in flight belongs to the previous stream
      next_ns = NowNs();
    }
    FillFrame(format, size, number, frame);
    size_t at = 0;
    while (at < frame.size()) {
      const size_t n = std::min<size_t>(frame.size() - at, kMaxPayload - 2);
      payload[0] = 2;
      payload[1] = static_cast<uint8_t>(UVC_STREAM_EOH | fid |
                                        (at + n == frame.size() ? UVC_STREAM_EOF : 0));
      std::memcpy(&payload[2], &frame[at], n);
      if (write(ep.load(), payload.data(), n + 2) < 0) {
        std::printf("GADGET write failed: %s\n", ErrnoText(errno).c_str());
        std::fflush(stdout);
        usleep(100000);
        break;
      }
      at += n;
    }
    ++number;
    fid ^= 1;
    next_ns += kInterval * 100LL;
    const int64_t now = NowNs();
    if (next_ns < now) next_ns = now;  // late: send the next frame at once, do not burst
    timespec t{static_cast<time_t>(next_ns / 1'000'000'000),
               static_cast<long>(next_ns % 1'000'000'000)};
    clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &t, nullptr);
  }
}

}  // namespace

int main(int argc, char** argv) {
  setvbuf(stdout, nullptr, _IOLBF, 0);
  if (argc > 2 && std::string(argv[2]) == "nv12") kFormats = kNv12Formats;
  if (argc > 1) {
    FILE* f = std::fopen(argv[1], "rb");
    if (f != nullptr) {
      char buf[65536];
      for (size_t n; (n = std::fread(buf, 1, sizeof buf, f)) > 0;) jpeg.append(buf, n);
      std::fclose(f);
    }
  }
  if (jpeg.size() < 4) {
    std::printf("GADGET needs a JPEG file as its argument\n");
    return 1;
  }
  FillProbe(&stream.probe, 1, 1);
  ep0 = open("/dev/gadget/dummy_udc", O_RDWR);
  if (ep0 < 0) {
    std::printf("GADGET cannot open /dev/gadget/dummy_udc: %s\n", ErrnoText(errno).c_str());
    return 1;
  }
  Bytes all;
  all.u32(0).add(ConfigDescriptor(64)).add(ConfigDescriptor(512)).add(DeviceDescriptor());
  std::printf("GADGET configuration descriptor: %zu bytes\n", ConfigDescriptor(512).b.size());
  if (write(ep0, all.b.data(), all.b.size()) < 0) {
    std::printf("GADGET descriptors refused: %s\n", ErrnoText(errno).c_str());
    return 1;
  }
  std::printf("GADGET bound\n");
  std::thread(StreamLoop).detach();
  // gadgetfs lets the host finish an OUT control transfer's data stage before
  // userspace has read the data; a host request that follows at once (SET_CUR
  // then GET_CUR of the probe control) then aborts the one being read. Answering
  // ep0 ahead of everything else in the guest (real-time priority; the stream
  // thread, started before, keeps the normal policy) closes that window.
  sched_param rt{};
  rt.sched_priority = 50;
  if (pthread_setschedparam(pthread_self(), SCHED_FIFO, &rt) != 0)
    std::printf("GADGET no real-time priority\n");
  int read_errors = 0;
  for (;;) {
    usb_gadgetfs_event events[5];
    const ssize_t n = read(ep0, events, sizeof events);
    if (n < 0) {
      // A host that gave up on a slow answer (a loaded machine slows the guest)
      // leaves a request pending: the read stalls it and the host retries.
      if (errno == EINTR || errno == EAGAIN) continue;
      std::printf("GADGET ep0 read: %s (continuing)\n", ErrnoText(errno).c_str());
      if (++read_errors > 1000) return 1;
      usleep(10000);
      continue;
    }
    for (ssize_t i = 0; i < n / static_cast<ssize_t>(sizeof events[0]); ++i) {
      switch (events[i].type) {
        case GADGETFS_CONNECT: {
          std::lock_guard<std::mutex> lock(stream.mutex);
          stream.speed = events[i].u.speed;
          std::printf("GADGET connected, speed %u\n", stream.speed);
          break;
        }
        case GADGETFS_SETUP:
          Setup(events[i].u.setup);
          break;
        case GADGETFS_DISCONNECT:
          std::printf("GADGET disconnected\n");
          break;
        default:
          break;
      }
    }
  }
}
