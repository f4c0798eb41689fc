#include "capture/libcamera/libcamera_source.h"

#include <libcamera/libcamera.h>
#include <sys/mman.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <mutex>
#include <ostream>
#include <streambuf>
#include <utility>

#include "core/error.h"
#include "core/log.h"
#include "core/option_checks.h"
#include "core/posix.h"

namespace ss {
namespace {

namespace lc = libcamera;

constexpr int kWaitSliceMs = 100;  // Next() checks for Stop() this often

struct LibcameraFormat {
  PixelFormat format;
  lc::PixelFormat libcamera;
};

// libcamera names formats after DRM: RGB888 is stored B, G, R (V4L2's BGR24).
const LibcameraFormat kLibcameraFormats[] = {
    {PixelFormat::kYUYV, lc::formats::YUYV},   {PixelFormat::kNV12, lc::formats::NV12},
    {PixelFormat::kMJPEG, lc::formats::MJPEG}, {PixelFormat::kBGR8, lc::formats::RGB888},
    {PixelFormat::kRGB8, lc::formats::BGR888},
};

std::optional<PixelFormat> FromLibcamera(const lc::PixelFormat& f) {
  for (const auto& e : kLibcameraFormats) {
    if (e.libcamera == f) return e.format;
  }
  return std::nullopt;
}

std::optional<lc::PixelFormat> ToLibcamera(PixelFormat f) {
  for (const auto& e : kLibcameraFormats) {
    if (e.format == f) return e.libcamera;
  }
  return std::nullopt;
}

std::string Names(const std::vector<lc::PixelFormat>& formats) {
  std::string out;
  for (const auto& f : formats) out += (out.empty() ? "" : ", ") + f.toString();
  return out.empty() ? "nothing" : out;
}

// libcamera's own log lines go to spdlog ("capture.libcamera"): warnings and
// errors as warnings, the rest at debug. LIBCAMERA_LOG_FILE still wins.
class LogLines : public std::streambuf {
 protected:
  int overflow(int c) override {
    if (c == traits_type::eof()) return 0;
    std::lock_guard<std::mutex> lock(mutex_);
    if (c == '\n') {
      Flush();
    } else {
      line_ += static_cast<char>(c);
    }
    return c;
  }
  std::streamsize xsputn(const char* s, std::streamsize n) override {
    std::lock_guard<std::mutex> lock(mutex_);
    for (std::streamsize i = 0; i < n; ++i) {
      if (s[i] == '\n') {
        Flush();
      } else {
        line_ += s[i];
      }
    }
    return n;
  }

 private:
  void Flush() {
    // No IPA modules (Debian's libcamera-ipa) matters to sensor pipelines only, not to UVC.
    const bool no_ipa = line_.find("No IPA found") != std::string::npos;
    const bool serious = !no_ipa && (line_.find(" WARN ") != std::string::npos ||
                                     line_.find(" ERROR ") != std::string::npos ||
                                     line_.find(" FATAL ") != std::string::npos);
    if (serious) {
      Log("capture.libcamera")->warn("libcamera: {}", line_);
    } else {
      Log("capture.libcamera")->debug("libcamera: {}", line_);
    }
    line_.clear();
  }
  std::mutex mutex_;
  std::string line_;
};

void RouteLibcameraLog() {
  static std::once_flag once;
  std::call_once(once, [] {
    if (Environment("LIBCAMERA_LOG_FILE")) return;
    static auto* buffer = new LogLines();  // libcamera logs until the process ends
    static auto* stream = new std::ostream(buffer);
    lc::logSetStream(stream, false);
  });
}

// libcamera allows one CameraManager per process: every source and listing
// shares it, and it stops when the last one lets go.
std::mutex manager_mutex;
std::condition_variable manager_gone;
std::weak_ptr<lc::CameraManager> manager_shared;
bool manager_alive = false;

std::shared_ptr<lc::CameraManager> SharedManager() {
  std::unique_lock<std::mutex> lock(manager_mutex);
  for (;;) {
    if (auto m = manager_shared.lock()) return m;
    if (!manager_alive) break;
    manager_gone.wait(lock);  // the previous one is being stopped
  }
  RouteLibcameraLog();
  auto* raw = new lc::CameraManager();
  const int r = raw->start();
  if (r < 0) {
    delete raw;
    throw WorkError("libcamera",
                    std::string("the camera manager does not start: ") + ErrnoText(-r));
  }
  std::shared_ptr<lc::CameraManager> m(raw, [](lc::CameraManager* cm) {
    cm->stop();
    delete cm;
    std::lock_guard<std::mutex> l(manager_mutex);
    manager_alive = false;
    manager_gone.notify_all();
  });
  manager_alive = true;
  manager_shared = m;
  return m;
}

std::vector<std::string> CameraIds(const lc::CameraManager& manager) {
  std::vector<std::string> ids;
  for (const auto& c : manager.cameras()) ids.push_back(c->id());
  return ids;
}

double AsNumber(const lc::ControlValue& v) {
  if (v.isArray() || v.numElements() != 1) return std::nan("");
  switch (v.type()) {
    case lc::ControlTypeInteger32:
      return v.get<int32_t>();
    case lc::ControlTypeInteger64:
      return static_cast<double>(v.get<int64_t>());
    case lc::ControlTypeFloat:
      return v.get<float>();
    case lc::ControlTypeByte:
      return v.get<uint8_t>();
    default:
      return std::nan("");
  }
}

std::string Num(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

// An mmap of one dmabuf, unmapped when the source ends.
struct Mapping {
  void* start = MAP_FAILED;
  size_t length = 0;
};

}  // namespace

std::optional<std::string> LibcameraFormatName(PixelFormat format) {
  const auto f = ToLibcamera(format);
  if (!f) return std::nullopt;
  return f->toString();
}

std::optional<PixelFormat> FromLibcameraFormatName(const std::string& name) {
  for (const auto& e : kLibcameraFormats) {
    if (e.libcamera.toString() == name) return e.format;
  }
  return std::nullopt;
}

LibcameraControlPlan PlanLibcameraControls(
    const LibcameraOptions& o, const std::map<std::string, LibcameraControlRange>& listed) {
  LibcameraControlPlan plan;
  auto listed_range = [&](const std::string& name) -> const LibcameraControlRange* {
    const auto it = listed.find(name);
    return it == listed.end() ? nullptr : &it->second;
  };
  auto ignore = [&](const std::string& control, const std::string& option) {
    plan.ignored.push_back(control + " (" + option + "): the camera does not list it");
  };
  auto check = [&](const LibcameraControlRange& r, double value, const std::string& option,
                   const std::string& what) {
    if ((!std::isnan(r.min) && value < r.min) || (!std::isnan(r.max) && value > r.max)) {
      throw InputError(option, what + " " + Num(value) + " is outside the camera's range " +
                                   Num(r.min) + ".." + Num(r.max));
    }
  };
  if (o.exposure_us > 0) {
    if (const auto* r = listed_range("ExposureTime")) {
      const double us = std::round(o.exposure_us);
      check(*r, us, "exposure_us", "ExposureTime (us)");
      plan.exposure_time_us = static_cast<int32_t>(us);
    } else {
      ignore("ExposureTime", "exposure_us");
    }
  }
  if (o.analogue_gain > 0) {
    if (const auto* r = listed_range("AnalogueGain")) {
      check(*r, o.analogue_gain, "gain", "AnalogueGain");
      plan.analogue_gain = static_cast<float>(o.analogue_gain);
    } else {
      ignore("AnalogueGain", "gain");
    }
  }
  // Exposure is always locked (a keyer needs it fixed): at the values asked for,
  // else at the camera's current ones.
  if (listed_range("AeEnable")) {
    plan.ae_enable = false;
  } else if (o.exposure_us > 0 || o.analogue_gain > 0) {
    ignore("AeEnable", o.exposure_us > 0 ? "exposure_us" : "gain");
  }
  if (o.white_balance == LibcameraWhiteBalance::kManual) {
    if (listed_range("AwbEnable")) {
      plan.awb_enable = false;
    } else {
      ignore("AwbEnable", "white_balance");
    }
    if (const auto* r = listed_range("ColourGains")) {
      check(*r, o.red_gain, "white_balance.red_gain", "ColourGains red");
      check(*r, o.blue_gain, "white_balance.blue_gain", "ColourGains blue");
      plan.colour_gains =
          std::array<float, 2>{static_cast<float>(o.red_gain), static_cast<float>(o.blue_gain)};
    } else {
      ignore("ColourGains", "white_balance");
    }
  } else if (o.white_balance == LibcameraWhiteBalance::kOnce) {
    if (listed_range("AwbEnable")) {
      plan.awb_enable = true;
      plan.lock_awb_after_settling = true;
    } else {
      ignore("AwbEnable", "white_balance");
    }
  }
  if (o.fps > 0) {
    if (const auto* r = listed_range("FrameDurationLimits")) {
      const auto us = static_cast<int64_t>(std::llround(1e6 / o.fps));
      check(*r, static_cast<double>(us), "fps", "FrameDurationLimits (us)");
      plan.frame_duration_limits_us = std::array<int64_t, 2>{us, us};
    } else {
      ignore("FrameDurationLimits", "fps");
    }
  }
  return plan;
}

std::vector<LibcameraCameraInfo> ListLibcameraCameras() {
  const auto manager = SharedManager();
  std::vector<LibcameraCameraInfo> out;
  for (const auto& camera : manager->cameras()) {
    LibcameraCameraInfo info;
    info.id = camera->id();
    const lc::ControlList& props = camera->properties();
    if (const auto model = props.get(lc::properties::Model)) info.model = *model;
    if (const auto location = props.get(lc::properties::Location)) {
      info.location = *location == lc::properties::CameraLocationFront  ? "front"
                      : *location == lc::properties::CameraLocationBack ? "back"
                                                                        : "external";
    }
    if (auto config = camera->generateConfiguration({lc::StreamRole::VideoRecording});
        config && !config->empty()) {
      for (const auto& f : config->at(0).formats().pixelformats()) {
        const auto ours = FromLibcamera(f);
        if (ours &&
            std::find(info.formats.begin(), info.formats.end(), *ours) == info.formats.end()) {
          info.formats.push_back(*ours);
        }
      }
    }
    out.push_back(info);
  }
  return out;
}

struct LibcameraSource::Impl : std::enable_shared_from_this<Impl> {
  LibcameraOptions options;
  std::shared_ptr<lc::CameraManager> manager;
  std::shared_ptr<lc::Camera> camera;
  bool acquired = false;
  bool started = false;
  std::unique_ptr<lc::CameraConfiguration> config;
  lc::Stream* stream = nullptr;
  std::unique_ptr<lc::FrameBufferAllocator> allocator;
  std::vector<std::unique_ptr<lc::Request>> requests;
  std::map<const lc::FrameBuffer*, std::vector<const uint8_t*>>
      plane_data;  // each plane's first byte
  std::vector<Mapping> maps;
  std::vector<SourceCamera> cameras;
  std::vector<std::string> listed;
  LibcameraControlPlan plan;
  PixelFormat format = PixelFormat::kYUYV;
  int width = 0;
  int height = 0;
  size_t stride = 0;
  std::atomic<bool> stopped{false};

  mutable std::mutex mutex;  // guards everything below and the requeueing
  std::condition_variable ready_cv;
  std::deque<lc::Request*> ready;  // completed, not yet returned by Next()
  bool running = false;            // requests may be queued
  bool disconnected = false;
  lc::ControlList pending;  // controls for the next request queued
  SourceStats totals;
  bool have_sequence = false;
  uint64_t last_sequence = 0;
  uint64_t frames_seen = 0;
  int waited_ms = 0;

  const std::string& id() const { return options.camera_id; }

  ~Impl() {
    Shutdown();
    if (camera) {
      camera->requestCompleted.disconnect(this);
      camera->disconnected.disconnect(this);
    }
    requests.clear();
    for (auto& m : maps) {
      if (m.start != MAP_FAILED) munmap(m.start, m.length);
    }
    if (allocator && stream) allocator->free(stream);
    allocator.reset();
    if (camera && acquired) camera->release();
    camera.reset();
    manager.reset();
  }

  // Stops the camera; frames still held keep their buffers until they die.
  void Shutdown() {
    {
      std::lock_guard<std::mutex> lock(mutex);
      running = false;
    }
    if (started) {
      camera->stop();  // completes the queued requests as cancelled, on libcamera's thread
      started = false;
    }
  }

  // libcamera's thread.
  void OnRequestCompleted(lc::Request* request) {
    if (request->status() == lc::Request::RequestCancelled) return;
    std::lock_guard<std::mutex> lock(mutex);
    ready.push_back(request);
    ready_cv.notify_one();
  }

  void OnDisconnected() {
    std::lock_guard<std::mutex> lock(mutex);
    disconnected = true;
    ready_cv.notify_all();
  }

  void Problem(const std::string& message) {
    Log("capture.libcamera")->warn("{}", message);
    ++totals.errors;
    totals.last_error = message;
  }

  // Gives a request back to the camera; the mutex is held.
  void RequeueLocked(lc::Request* request) {
    if (!running) return;
    request->reuse(lc::Request::ReuseBuffers);
    if (!pending.empty()) {
      request->controls().merge(pending);
      pending.clear();
    }
    const int r = camera->queueRequest(request);
    if (r < 0) Problem(id() + ": cannot queue a request back: " + ErrnoText(-r));
  }

  void Requeue(lc::Request* request) {
    std::lock_guard<std::mutex> lock(mutex);
    RequeueLocked(request);
  }
};

bool LibcameraOptions::IsValid(std::string* why) const {
  OptionProblems check(why);
  check.Within(camera_index, AtLeast(0), "camera_index", "a number >= 0");
  check(!pixel_format || ToLibcamera(*pixel_format).has_value(), "pixel_format",
        "the libcamera backend reads yuyv, nv12, mjpeg, rgb8 and bgr8, not " +
            (pixel_format ? PixelFormatName(*pixel_format) : std::string()));
  check(width >= 0 && height >= 0 && (width > 0) == (height > 0), "width/height",
        "give both or neither (got " + std::to_string(width) + "x" + std::to_string(height) + ")");
  for (const auto& [v, field] :
       {std::pair{fps, "fps"}, {exposure_us, "exposure_us"}, {analogue_gain, "analogue_gain"}}) {
    check(std::isfinite(v) && v >= 0, field,
          "expected 0 (leave it) or a positive number, got " + OptionProblems::Num(v));
  }
  for (const auto& [v, field] : {std::pair{red_gain, "red_gain"}, {blue_gain, "blue_gain"}}) {
    check(std::isfinite(v) && v > 0, field,
          "expected a positive gain, got " + OptionProblems::Num(v));
  }
  check.Within(awb_settle_frames, AtLeast(1), "awb_settle_frames", "at least 1 frame");
  check.Within(buffers, AtLeast(2), "buffers", "2 or more");
  check.Within(frame_timeout_ms, AtLeast(1), "frame_timeout_ms", "at least 1 ms");
  return check.ok();
}

LibcameraSource::LibcameraSource(LibcameraOptions options) : impl_(std::make_shared<Impl>()) {
  Impl& s = *impl_;
  if (std::string why; !options.IsValid(&why)) throw InputError("libcamera options", why);
  s.manager = SharedManager();

  // The camera.
  const std::vector<std::string> ids = CameraIds(*s.manager);
  if (options.camera_id.empty()) {
    if (ids.empty())
      throw WorkError("libcamera",
                      "no cameras found (`spritestation cameras` lists what is present)");
    options.camera_id = ids.front();
  }
  s.options = options;
  s.camera = s.manager->get(options.camera_id);
  if (!s.camera) {
    std::string found;
    for (const auto& i : ids) found += (found.empty() ? "" : ", ") + i;
    throw WorkError(options.camera_id,
                    "no libcamera camera with this id (" +
                        (ids.empty() ? std::string("no cameras found") : "found: " + found) + ")");
  }
  const std::string& id = options.camera_id;
  if (const int r = s.camera->acquire(); r < 0) {
    if (r == -EBUSY)
      throw WorkError(id, "busy: another program or camera of this station holds it");
    throw WorkError(id, std::string("cannot acquire: ") + ErrnoText(-r));
  }
  s.acquired = true;
  for (const auto& [control, info] : s.camera->controls()) s.listed.push_back(control->name());
  std::sort(s.listed.begin(), s.listed.end());

  // Format and size.
  s.config = s.camera->generateConfiguration({lc::StreamRole::VideoRecording});
  if (!s.config || s.config->empty())
    s.config = s.camera->generateConfiguration({lc::StreamRole::Viewfinder});
  if (!s.config || s.config->empty()) throw WorkError(id, "offers no video stream");
  lc::StreamConfiguration& sc = s.config->at(0);
  const std::vector<lc::PixelFormat> offered = sc.formats().pixelformats();
  lc::PixelFormat want = sc.pixelFormat;
  if (options.pixel_format) {
    want = *ToLibcamera(*options.pixel_format);
    if (std::find(offered.begin(), offered.end(), want) == offered.end()) {
      throw InputError("pixel_format",
                       id + " does not offer " + PixelFormatName(*options.pixel_format) + " (" +
                           want.toString() + "; it offers: " + Names(offered) + ")");
    }
  } else if (!FromLibcamera(want)) {
    for (const auto& f : offered) {
      if (FromLibcamera(f)) {
        want = f;
        break;
      }
    }
  }
  sc.pixelFormat = want;
  if (options.width > 0)
    sc.size = lc::Size(static_cast<unsigned>(options.width), static_cast<unsigned>(options.height));
  const lc::Size want_size = sc.size;
  sc.bufferCount = static_cast<unsigned>(options.buffers);
  if (s.config->validate() == lc::CameraConfiguration::Invalid) {
    throw InputError("pixel_format",
                     id + " refuses " + want.toString() + " " + want_size.toString());
  }
  const auto format = FromLibcamera(sc.pixelFormat);
  if (!format) {
    throw InputError("pixel_format",
                     id + " delivers " + sc.pixelFormat.toString() +
                         ", which SpriteStation does not read (it offers: " + Names(offered) + ")");
  }
  if (sc.pixelFormat != want) {
    throw InputError("pixel_format", id + " does not take " + want.toString() +
                                         " (it offers: " + Names(offered) + ")");
  }
  if (sc.size != want_size) {
    std::string sizes;
    for (const auto& z : sc.formats().sizes(want))
      sizes += (sizes.empty() ? "" : ", ") + z.toString();
    throw InputError("width/height", id + " cannot capture " + want.toString() + " at " +
                                         want_size.toString() + " (nearest: " + sc.size.toString() +
                                         "; sizes: " + sizes + ")");
  }
  if (const int r = s.camera->configure(s.config.get()); r < 0) {
    throw WorkError(id, "cannot configure " + sc.toString() + ": " + ErrnoText(-r));
  }
  s.format = *format;
  s.width = static_cast<int>(sc.size.width);
  s.height = static_cast<int>(sc.size.height);
  s.stride = sc.stride;
  s.stream = sc.stream();

  // Controls.
  std::map<std::string, LibcameraControlRange> ranges;
  for (const auto& [control, info] : s.camera->controls()) {
    ranges[control->name()] = LibcameraControlRange{AsNumber(info.min()), AsNumber(info.max())};
  }
  s.plan = PlanLibcameraControls(options, ranges);
  for (const auto& ignored : s.plan.ignored)
    Log("capture.libcamera")->warn("{}: ignored {}", id, ignored);
  lc::ControlList controls(s.camera->controls());
  if (s.plan.ae_enable) controls.set(lc::controls::AeEnable, *s.plan.ae_enable);
  if (s.plan.exposure_time_us) controls.set(lc::controls::ExposureTime, *s.plan.exposure_time_us);
  if (s.plan.analogue_gain) controls.set(lc::controls::AnalogueGain, *s.plan.analogue_gain);
  if (s.plan.awb_enable) controls.set(lc::controls::AwbEnable, *s.plan.awb_enable);
  if (s.plan.colour_gains) {
    controls.set(lc::controls::ColourGains, {(*s.plan.colour_gains)[0], (*s.plan.colour_gains)[1]});
  }
  if (s.plan.frame_duration_limits_us) {
    controls.set(lc::controls::FrameDurationLimits,
                 {(*s.plan.frame_duration_limits_us)[0], (*s.plan.frame_duration_limits_us)[1]});
  }
  s.pending = lc::ControlList(s.camera->controls());

  // Buffers, mapped once, and one request per buffer.
  s.allocator = std::make_unique<lc::FrameBufferAllocator>(s.camera);
  if (const int r = s.allocator->allocate(s.stream); r < 0) {
    throw WorkError(id, std::string("cannot allocate buffers: ") + ErrnoText(-r));
  }
  const auto& buffers = s.allocator->buffers(s.stream);
  if (buffers.size() < 2)
    throw WorkError(id, "libcamera gave " + std::to_string(buffers.size()) + " buffer(s); need 2");
  for (const auto& buffer : buffers) {
    std::map<int, size_t> extent;  // dmabuf fd -> bytes to map
    for (const auto& plane : buffer->planes()) {
      const size_t offset =
          plane.offset == lc::FrameBuffer::Plane::kInvalidOffset ? 0 : plane.offset;
      extent[plane.fd.get()] = std::max(extent[plane.fd.get()], offset + plane.length);
    }
    std::map<int, const uint8_t*> base;
    for (const auto& [fd, length] : extent) {
      Mapping m;
      m.length = length;
      m.start = mmap(nullptr, length, PROT_READ, MAP_SHARED, fd, 0);
      if (m.start == MAP_FAILED)
        throw WorkError(id, std::string("cannot map a buffer: ") + ErrnoText(errno));
      s.maps.push_back(m);
      base[fd] = static_cast<const uint8_t*>(m.start);
    }
    auto& data = s.plane_data[buffer.get()];
    for (const auto& plane : buffer->planes()) {
      const size_t offset =
          plane.offset == lc::FrameBuffer::Plane::kInvalidOffset ? 0 : plane.offset;
      data.push_back(base[plane.fd.get()] + offset);
    }
    std::unique_ptr<lc::Request> request = s.camera->createRequest();
    if (!request) throw WorkError(id, "cannot create a request");
    if (const int r = request->addBuffer(s.stream, buffer.get()); r < 0) {
      throw WorkError(id, std::string("cannot attach a buffer to a request: ") + ErrnoText(-r));
    }
    // Some pipelines (UVC) take controls only with requests: the first carries them too.
    if (s.requests.empty()) request->controls().merge(controls);
    s.requests.push_back(std::move(request));
  }

  s.camera->requestCompleted.connect(impl_.get(), &Impl::OnRequestCompleted);
  s.camera->disconnected.connect(impl_.get(), &Impl::OnDisconnected);
  if (const int r = s.camera->start(&controls); r < 0) {
    if (r == -EBUSY) throw WorkError(id, "busy: another program is streaming from it");
    throw WorkError(id, std::string("cannot start: ") + ErrnoText(-r));
  }
  s.started = true;
  {
    std::lock_guard<std::mutex> lock(s.mutex);
    s.running = true;
    for (auto& request : s.requests) {
      if (const int r = s.camera->queueRequest(request.get()); r < 0) {
        throw WorkError(id, std::string("cannot queue a request: ") + ErrnoText(-r));
      }
    }
  }

  SourceCamera cam;
  cam.name = options.name.empty() ? id : options.name;
  cam.width = s.width;
  cam.height = s.height;
  cam.format = s.format;
  cam.fps = s.plan.frame_duration_limits_us
                ? 1e6 / static_cast<double>((*s.plan.frame_duration_limits_us)[0])
                : 0.0;
  s.cameras.push_back(cam);
  Log("capture.libcamera")
      ->info("{}: streaming {} (stride {}), {} buffers, controls set: {}", id, sc.toString(),
             s.stride, buffers.size(), controls.size());
}

LibcameraSource::~LibcameraSource() {
  Stop();
  impl_->Shutdown();
}

const std::vector<SourceCamera>& LibcameraSource::cameras() const { return impl_->cameras; }

std::optional<Frame> LibcameraSource::Next() {
  Impl& s = *impl_;
  std::unique_lock<std::mutex> lock(s.mutex);
  while (!s.stopped.load()) {
    if (s.disconnected) throw WorkError(s.id(), "the camera disconnected while streaming");
    if (s.ready.empty()) {
      const bool woke = s.ready_cv.wait_for(lock, std::chrono::milliseconds(kWaitSliceMs), [&] {
        return !s.ready.empty() || s.disconnected || s.stopped.load();
      });
      if (!woke) {
        s.waited_ms += kWaitSliceMs;
        if (s.waited_ms >= s.options.frame_timeout_ms) {
          s.Problem(s.id() + ": no frame for " + std::to_string(s.waited_ms) + " ms");
          s.waited_ms = 0;
        }
      }
      continue;
    }
    lc::Request* request = s.ready.front();
    s.ready.pop_front();
    s.waited_ms = 0;
    const lc::FrameBuffer* buffer = request->findBuffer(s.stream);
    if (buffer == nullptr) {
      s.Problem(s.id() + ": a completed request without its buffer");
      s.RequeueLocked(request);
      continue;
    }
    const lc::FrameMetadata& meta = buffer->metadata();
    const uint64_t sequence = meta.sequence;
    if (s.have_sequence && sequence > s.last_sequence + 1)
      s.totals.frames_dropped += sequence - s.last_sequence - 1;
    s.have_sequence = true;
    s.last_sequence = sequence;
    const auto& planes = meta.planes();
    size_t used = 0;
    for (const auto& p : planes) used += p.bytesused;
    const size_t packed = FrameBytes(s.format, s.width, s.height);
    const size_t expected = s.format == PixelFormat::kNV12
                                ? s.stride * static_cast<size_t>(s.height) * 3 / 2
                                : s.stride * static_cast<size_t>(s.height);
    std::string problem;
    if (meta.status != lc::FrameMetadata::FrameSuccess) {
      problem = "libcamera flagged it failed";
    } else if (s.format == PixelFormat::kMJPEG && (planes.empty() || planes[0].bytesused == 0)) {
      problem = "empty JPEG";
    } else if (s.format != PixelFormat::kMJPEG && used < expected) {
      problem = "short frame (" + std::to_string(used) + " bytes, expected " +
                std::to_string(expected) + ")";
    }
    if (!problem.empty()) {
      ++s.totals.frames_dropped;
      s.Problem(s.id() + ": frame " + std::to_string(sequence) + ": " + problem);
      s.RequeueLocked(request);
      continue;
    }
    ++s.totals.frames_delivered;
    ++s.frames_seen;
    const lc::ControlList& results = request->metadata();
    int64_t timestamp_ns = static_cast<int64_t>(meta.timestamp);
    if (const auto sensor = results.get(lc::controls::SensorTimestamp)) timestamp_ns = *sensor;
    if (s.plan.lock_awb_after_settling &&
        s.frames_seen == static_cast<uint64_t>(s.options.awb_settle_frames)) {
      s.pending.set(lc::controls::AwbEnable, false);
      if (const auto gains = results.get(lc::controls::ColourGains)) {
        s.pending.set(lc::controls::ColourGains, {(*gains)[0], (*gains)[1]});
      }
      Log("capture.libcamera")
          ->info("{}: white balance locked after {} frames", s.id(), s.frames_seen);
    }

    const std::vector<const uint8_t*>& data = s.plane_data[buffer];
    Frame f;
    auto self = impl_;
    auto release = [self, request] { self->Requeue(request); };
    if (s.format == PixelFormat::kMJPEG) {
      f = Frame::Borrowed(s.format, s.width, s.height, data[0], planes[0].bytesused, release);
    } else if (s.format == PixelFormat::kNV12
                   // NV12 borrowed when its rows are unpadded and its chroma follows its luma
                   ? s.stride == static_cast<size_t>(s.width) &&
                         (data.size() == 1 ||
                          data[1] == data[0] + static_cast<size_t>(s.width) * s.height)
                   // any other format when its rows are unpadded
                   : s.stride * static_cast<size_t>(s.height) == packed) {
      f = Frame::Borrowed(s.format, s.width, s.height, data[0], packed, release);
    } else {
      // Padded rows or separate planes: repack into an owned frame and give the buffer straight
      // back.
      std::vector<uint8_t> pixels(packed);
      const size_t row =
          packed / (s.format == PixelFormat::kNV12 ? static_cast<size_t>(s.height) * 3 / 2
                                                   : static_cast<size_t>(s.height));
      const size_t luma_rows = static_cast<size_t>(s.height);
      const size_t rows = pixels.size() / row;
      for (size_t y = 0; y < rows; ++y) {
        const uint8_t* from = nullptr;
        if (s.format == PixelFormat::kNV12 && y >= luma_rows) {
          const uint8_t* chroma = data.size() > 1 ? data[1] : data[0] + s.stride * luma_rows;
          from = chroma + (y - luma_rows) * s.stride;
        } else {
          from = data[0] + y * s.stride;
        }
        std::memcpy(&pixels[y * row], from, row);
      }
      s.RequeueLocked(request);
      f = Frame::Owned(s.format, s.width, s.height, std::move(pixels));
    }
    f.camera = s.options.camera_index;
    f.sequence = sequence;
    f.timestamp_ns = timestamp_ns;
    return f;
  }
  return std::nullopt;
}

void LibcameraSource::Stop() {
  impl_->stopped.store(true);
  std::lock_guard<std::mutex> lock(impl_->mutex);
  impl_->ready_cv.notify_all();
}

SourceStats LibcameraSource::stats() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->totals;
}

const std::vector<std::string>& LibcameraSource::ignored_controls() const {
  return impl_->plan.ignored;
}

const std::vector<std::string>& LibcameraSource::listed_controls() const { return impl_->listed; }

}  // namespace ss
