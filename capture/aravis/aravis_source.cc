#include "capture/aravis/aravis_source.h"

#include <arv.h>

#include <atomic>
#include <cmath>
#include <mutex>
#include <utility>

#include "capture/aravis/gobject_ptr.h"
#include "capture/aravis/pixel_formats.h"
#include "core/error.h"
#include "core/log.h"
#include "core/option_checks.h"

namespace ss {
namespace {

constexpr guint64 kPopSliceUs = 100'000;  // Next() checks for Stop() this often

// The camera and its stream, kept alive by the source and by every lent frame:
// a buffer goes back to the stream when its last frame dies, even after the source is gone.
struct StreamHolder {
  GObjectPtr<ArvCamera> camera;
  GObjectPtr<ArvStream> stream;
  ~StreamHolder() {
    stream.reset();  // stops the stream thread before the device goes
    camera.reset();
  }
};

std::string Str(const char* s) { return s != nullptr ? s : ""; }

}  // namespace

std::vector<AravisDeviceInfo> ListAravisDevices() {
  arv_update_device_list();
  std::vector<AravisDeviceInfo> out;
  const unsigned n = arv_get_n_devices();
  for (unsigned i = 0; i < n; ++i) {
    AravisDeviceInfo d;
    d.id = Str(arv_get_device_id(i));
    d.address = Str(arv_get_device_address(i));
    d.vendor = Str(arv_get_device_vendor(i));
    d.model = Str(arv_get_device_model(i));
    d.serial = Str(arv_get_device_serial_nbr(i));
    d.protocol = Str(arv_get_device_protocol(i));
    out.push_back(d);
  }
  return out;
}

struct AravisSource::Impl {
  AravisOptions options;
  std::string label;  // "aravis camera 'ID'", for messages
  std::shared_ptr<StreamHolder> holder;
  std::vector<SourceCamera> cameras;
  PixelFormat format = PixelFormat::kMono8;
  int packet_size = 0;
  std::atomic<bool> stopped{false};

  mutable std::mutex mutex;  // guards the counters below
  SourceStats totals;
  uint64_t sequence_gaps = 0;
  uint64_t incomplete_since_last = 0;  // incomplete frames since the last complete one
  bool have_last_id = false;
  uint64_t last_id = 0;
  uint64_t sequence = 0;
  int64_t waited_us = 0;

  void Check(GErrorHolder& error, const std::string& field, const std::string& what) {
    if (!error) return;
    throw InputError(field, label + " refuses " + what + ": " + error.message());
  }

  // White balance through the SFNC features (BalanceWhiteAuto, BalanceRatioSelector,
  // BalanceRatio): run once then locked, or fixed ratios. A camera without them (a mono or
  // raw Bayer camera, Aravis's fake camera) is refused: the keyer needs the colours fixed.
  void SetWhiteBalance(ArvCamera* cam, const AravisOptions& o) {
    const std::string field = "white_balance";
    const auto has = [&](const char* feature) {
      return arv_camera_is_feature_available(cam, feature, nullptr);
    };
    GErrorHolder error;
    if (o.white_balance == WhiteBalanceMode::kOnce) {
      if (!has("BalanceWhiteAuto")) {
        throw InputError(
            field,
            label +
                " has no BalanceWhiteAuto feature, so it cannot balance once (use mode device)");
      }
      arv_camera_set_string(cam, "BalanceWhiteAuto", "Once", error.out());
      Check(error, field, "BalanceWhiteAuto = Once");
      return;
    }
    if (!has("BalanceRatio") || !has("BalanceRatioSelector")) {
      throw InputError(field, label +
                                  " has no BalanceRatio feature: set its white balance on the "
                                  "camera and use mode device");
    }
    if (has("BalanceWhiteAuto")) {
      arv_camera_set_string(cam, "BalanceWhiteAuto", "Off", error.out());
      Check(error, field, "BalanceWhiteAuto = Off");
    }
    for (const auto& [channel, ratio] :
         {std::pair<const char*, double>{"Red", o.red_ratio}, {"Blue", o.blue_ratio}}) {
      arv_camera_set_string(cam, "BalanceRatioSelector", channel, error.out());
      Check(error, field, std::string("BalanceRatioSelector = ") + channel);
      arv_camera_set_float(cam, "BalanceRatio", ratio, error.out());
      Check(error, field + "." + (channel[0] == 'R' ? "red_gain" : "blue_gain"),
            std::string(channel) + " BalanceRatio " + std::to_string(ratio));
    }
  }

  // Widens the block id past the 16-bit wrap of GigE Vision 1.x (which skips 0)
  // and counts the ids jumped over. Call with the mutex held.
  uint64_t Sequence(uint64_t id) {
    if (!have_last_id) {
      have_last_id = true;
      last_id = id;
      sequence = id;
      return sequence;
    }
    uint64_t delta = 0;
    if (id > 0xffff || last_id > 0xffff) {
      delta = id > last_id ? id - last_id : 0;
    } else if (id >= last_id) {
      delta = id - last_id;
    } else {
      delta = id + 0xffff - last_id;  // wrapped: ids run 65535, 1, 2, ...
    }
    if (delta > 1)
      sequence_gaps += delta - 1 - std::min<uint64_t>(delta - 1, incomplete_since_last);
    incomplete_since_last = 0;
    last_id = id;
    sequence += delta;
    return sequence;
  }

  void Problem(const std::string& message) {
    Log("capture.aravis")->warn("{}", message);
    ++totals.errors;
    totals.last_error = message;
  }
};

bool AravisOptions::IsValid(std::string* why) const {
  OptionProblems check(why);
  check.Within(camera_index, AtLeast(0), "camera_index", "a number >= 0");
  check(!pixel_format || GenicamPixelFormat(*pixel_format).has_value(), "pixel_format",
        (pixel_format ? PixelFormatName(*pixel_format) : std::string()) +
            " is not a GigE/USB3 Vision format (use mono8, bayer_*8, rgb8, bgr8, yuyv)");
  check(width >= 0 && height >= 0 && (width > 0) == (height > 0), "width/height",
        "give both or neither (got " + std::to_string(width) + "x" + std::to_string(height) + ")");
  check.Within(exposure_us, AtLeast(0), "exposure_us",
               "0 (leave it) or a positive number of microseconds");
  check(std::isfinite(gain), "gain",
        "expected a number (< 0: leave it), got " + OptionProblems::Num(gain));
  check.Within(fps, AtLeast(0), "fps", "0 (leave it) or a positive frame rate");
  for (const auto& [v, field] : {std::pair{red_ratio, "red_ratio"}, {blue_ratio, "blue_ratio"}}) {
    check(std::isfinite(v) && v > 0, field,
          "expected a positive ratio, got " + OptionProblems::Num(v));
  }
  check.Within(packet_size, AtLeast(0), "packet_size", "0 (negotiate) or a number of bytes");
  check.Within(buffers, AtLeast(2), "buffers", "2 or more");
  check.Within(frame_timeout_ms, AtLeast(1), "frame_timeout_ms", "at least 1 ms");
  return check.ok();
}

AravisSource::AravisSource(AravisOptions options) : impl_(std::make_unique<Impl>()) {
  Impl& s = *impl_;
  s.options = options;
  s.label = "aravis camera '" +
            (options.camera.empty() ? std::string("(first found)") : options.camera) + "'";
  if (std::string why; !options.IsValid(&why)) throw InputError("aravis options", why);

  GErrorHolder error;
  auto holder = std::make_shared<StreamHolder>();
  // A GigE camera named by id or serial is opened through the address discovery
  // found it at, so the stream is set up on the interface that reaches it (on
  // loopback, opening by id would aim the stream at another interface).
  std::string target = options.camera;
  GInetAddress* literal =
      options.camera.empty() ? nullptr : g_inet_address_new_from_string(options.camera.c_str());
  if (literal != nullptr) {
    g_object_unref(literal);
  } else if (!options.camera.empty()) {
    for (const auto& d : ListAravisDevices()) {
      if ((d.id == options.camera || d.serial == options.camera) && d.protocol == "GigEVision" &&
          !d.address.empty()) {
        target = d.address;
        break;
      }
    }
  }
  holder->camera.reset(arv_camera_new(target.empty() ? nullptr : target.c_str(), error.out()));
  if (!holder->camera) {
    throw WorkError(
        s.label,
        "cannot open: " + (error ? error.message() : std::string("not found")) +
            " (is it connected and reachable? `spritestation cameras` lists what Aravis sees)");
  }
  ArvCamera* cam = holder->camera.get();
  const std::string serial = Str(arv_camera_get_device_serial_number(cam, error.out()));
  const std::string model = Str(arv_camera_get_model_name(cam, error.out()));
  error.Clear();

  if (options.pixel_format) {
    const auto code = GenicamPixelFormat(*options.pixel_format);  // IsValid: a GigE format
    arv_camera_set_pixel_format(cam, static_cast<ArvPixelFormat>(*code), error.out());
    s.Check(error, "pixel_format", GenicamPixelFormatName(*code));
  }
  if (options.width > 0) {
    arv_camera_set_region(cam, 0, 0, options.width, options.height, error.out());
    s.Check(error, "width/height",
            std::to_string(options.width) + "x" + std::to_string(options.height));
  }
  if (options.exposure_us > 0) {
    if (arv_camera_is_exposure_auto_available(cam, nullptr)) {
      arv_camera_set_exposure_time_auto(cam, ARV_AUTO_OFF, error.out());
      s.Check(error, "exposure_us", "turning auto exposure off");
    }
    arv_camera_set_exposure_time(cam, options.exposure_us, error.out());
    s.Check(error, "exposure_us", std::to_string(options.exposure_us) + " us");
  }
  if (options.gain >= 0) {
    if (arv_camera_is_gain_auto_available(cam, nullptr)) {
      arv_camera_set_gain_auto(cam, ARV_AUTO_OFF, error.out());
      s.Check(error, "gain", "turning auto gain off");
    }
    arv_camera_set_gain(cam, options.gain, error.out());
    s.Check(error, "gain", std::to_string(options.gain));
  }
  if (options.white_balance != WhiteBalanceMode::kDevice) s.SetWhiteBalance(cam, options);
  if (options.fps > 0) {
    arv_camera_set_frame_rate(cam, options.fps, error.out());
    s.Check(error, "fps", std::to_string(options.fps) + " frames/s");
  }
  arv_camera_set_acquisition_mode(cam, ARV_ACQUISITION_MODE_CONTINUOUS, error.out());
  s.Check(error, "acquisition_mode", "continuous acquisition");

  if (arv_camera_is_gv_device(cam)) {
    if (options.packet_size > 0) {
      arv_camera_gv_set_packet_size(cam, options.packet_size, error.out());
      s.Check(error, "packet_size", std::to_string(options.packet_size) + " bytes");
    } else {
      arv_camera_gv_auto_packet_size(cam, error.out());
      if (error)
        Log("capture.aravis")
            ->warn("{}: packet size negotiation failed: {}", s.label, error.message());
      error.Clear();
    }
    s.packet_size = static_cast<int>(arv_camera_gv_get_packet_size(cam, nullptr));
  }

  // What the camera will actually deliver.
  const uint32_t code = arv_camera_get_pixel_format(cam, error.out());
  s.Check(error, "pixel_format", "reading the pixel format");
  const auto format = FromGenicamPixelFormat(code);
  if (!format) {
    throw InputError(
        "pixel_format",
        s.label + " delivers " + GenicamPixelFormatName(code) +
            ", which SpriteStation does not read (choose Mono8, Bayer*8, RGB8, BGR8 or "
            "YUV422_8 in the camera config)");
  }
  s.format = *format;
  gint x = 0, y = 0, width = 0, height = 0;
  arv_camera_get_region(cam, &x, &y, &width, &height, error.out());
  s.Check(error, "width/height", "reading the region");
  double fps = arv_camera_get_frame_rate(cam, error.out());
  if (error) fps = 0.0;
  error.Clear();

  holder->stream.reset(arv_camera_create_stream(cam, nullptr, nullptr, error.out()));
  if (!holder->stream) throw WorkError(s.label, "cannot create the stream: " + error.message());
  ArvStream* stream = holder->stream.get();
  if (ARV_IS_GV_STREAM(stream)) {
    g_object_set(stream, "packet-resend",
                 options.packet_resend ? ARV_GV_STREAM_PACKET_RESEND_ALWAYS
                                       : ARV_GV_STREAM_PACKET_RESEND_NEVER,
                 nullptr);
  }
  const guint payload = arv_camera_get_payload(cam, error.out());
  s.Check(error, "payload", "reading the payload size");
  for (int i = 0; i < options.buffers; ++i)
    arv_stream_push_buffer(stream, arv_buffer_new(payload, nullptr));

  SourceCamera sc;
  sc.name = !options.name.empty() ? options.name : (!serial.empty() ? serial : options.camera);
  sc.width = width;
  sc.height = height;
  sc.format = s.format;
  sc.fps = fps;
  s.cameras.push_back(sc);
  s.holder = std::move(holder);

  arv_camera_start_acquisition(cam, error.out());
  if (error) throw WorkError(s.label, "cannot start acquisition: " + error.message());
  Log("capture.aravis")
      ->info("{}: {} {} streaming {} {}x{} at {:.1f} frames/s, packet size {}, resend {}", s.label,
             model, serial, PixelFormatName(s.format), width, height, fps, s.packet_size,
             options.packet_resend ? "on" : "off");
}

AravisSource::~AravisSource() {
  Stop();
  if (impl_->holder && impl_->holder->camera)
    arv_camera_stop_acquisition(impl_->holder->camera.get(), nullptr);
}

const std::vector<SourceCamera>& AravisSource::cameras() const { return impl_->cameras; }

std::optional<Frame> AravisSource::Next() {
  Impl& s = *impl_;
  ArvStream* stream = s.holder->stream.get();
  while (!s.stopped.load()) {
    ArvBuffer* buffer = arv_stream_timeout_pop_buffer(stream, kPopSliceUs);
    if (buffer == nullptr) {
      std::lock_guard<std::mutex> lock(s.mutex);
      s.waited_us += static_cast<int64_t>(kPopSliceUs);
      if (s.waited_us >= static_cast<int64_t>(s.options.frame_timeout_ms) * 1000) {
        s.Problem(s.label + ": no frame for " + std::to_string(s.waited_us / 1000) + " ms");
        s.waited_us = 0;
      }
      continue;
    }
    const ArvBufferStatus status = arv_buffer_get_status(buffer);
    const uint64_t id = arv_buffer_get_frame_id(buffer);
    std::unique_lock<std::mutex> lock(s.mutex);
    s.waited_us = 0;
    // An incomplete frame's block id may be lost with its leader packet (Aravis gives 0):
    // it is counted as dropped itself, and the next complete frame's gap does not count it again.
    if (status != ARV_BUFFER_STATUS_SUCCESS) {
      ++s.incomplete_since_last;
    }
    const uint64_t sequence = status == ARV_BUFFER_STATUS_SUCCESS ? s.Sequence(id) : s.sequence;
    size_t size = 0;
    const uint8_t* data = nullptr;
    int width = 0;
    int height = 0;
    std::string problem;
    if (status != ARV_BUFFER_STATUS_SUCCESS) {
      problem = "incomplete frame (status " + std::to_string(static_cast<int>(status)) + ")";
    } else if (arv_buffer_get_payload_type(buffer) != ARV_BUFFER_PAYLOAD_TYPE_IMAGE) {
      problem = "not an image (payload type " +
                std::to_string(static_cast<int>(arv_buffer_get_payload_type(buffer))) + ")";
    } else {
      data = static_cast<const uint8_t*>(arv_buffer_get_image_data(buffer, &size));
      width = arv_buffer_get_image_width(buffer);
      height = arv_buffer_get_image_height(buffer);
    }
    if (problem.empty() &&
        FromGenicamPixelFormat(arv_buffer_get_image_pixel_format(buffer)) != s.format) {
      problem = "pixel format changed to " +
                GenicamPixelFormatName(arv_buffer_get_image_pixel_format(buffer));
    } else if (problem.empty() && (data == nullptr || size < FrameBytes(s.format, width, height) ||
                                   width <= 0 || height <= 0)) {
      problem = "short frame (" + std::to_string(size) + " bytes for " + std::to_string(width) +
                "x" + std::to_string(height) + ")";
    }
    if (!problem.empty()) {
      ++s.totals.frames_dropped;
      s.Problem(s.label + ": frame " + std::to_string(sequence) + " (block id " +
                std::to_string(id) + "): " + problem);
      lock.unlock();
      arv_stream_push_buffer(stream, buffer);
      continue;
    }
    ++s.totals.frames_delivered;
    lock.unlock();
    uint64_t timestamp_ns = arv_buffer_get_timestamp(buffer);
    if (timestamp_ns == 0) timestamp_ns = arv_buffer_get_system_timestamp(buffer);
    auto holder = s.holder;
    Frame f =
        Frame::Borrowed(s.format, width, height, data, FrameBytes(s.format, width, height),
                        [holder, buffer] { arv_stream_push_buffer(holder->stream.get(), buffer); });
    f.camera = s.options.camera_index;
    f.sequence = sequence;
    f.timestamp_ns = static_cast<int64_t>(timestamp_ns);
    return f;
  }
  return std::nullopt;
}

void AravisSource::Stop() { impl_->stopped.store(true); }

SourceStats AravisSource::stats() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  SourceStats out = impl_->totals;
  out.frames_dropped += impl_->sequence_gaps;
  return out;
}

AravisStreamStats AravisSource::stream_stats() const {
  ArvStream* stream = impl_->holder->stream.get();
  auto info = [stream](const char* name) {
    return arv_stream_get_info_uint64_by_name(stream, name);
  };
  AravisStreamStats out;
  out.completed = info("n_completed_buffers");
  out.failures = info("n_failures");
  out.underruns = info("n_underruns");
  out.timeouts = info("n_timeouts");
  if (ARV_IS_GV_STREAM(stream)) {
    out.missing_frames = info("n_missing_frames");
    out.received_packets = info("n_received_packets");
    out.missing_packets = info("n_missing_packets");
    out.resend_requests = info("n_resend_requests");
    out.resent_packets = info("n_resent_packets");
    out.transferred_bytes = info("n_transferred_bytes");
  }
  std::lock_guard<std::mutex> lock(impl_->mutex);
  out.sequence_gaps = impl_->sequence_gaps;
  return out;
}

int AravisSource::packet_size() const { return impl_->packet_size; }

}  // namespace ss
