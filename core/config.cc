#include "core/config.h"

#include <arpa/inet.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include "core/error.h"
#include "core/sql_postgres.h"
#include "core/frame.h"
#include "core/log.h"
#include "core/options_binder.h"
#include "core/recording_codecs.h"
#include "core/yaml_reader.h"

namespace ss {
namespace {

namespace fs = std::filesystem;

const std::vector<std::string> kSources = {"replay", "v4l2", "aravis", "libcamera"};
const std::vector<std::string> kLogLevels = {"trace", "debug",    "info", "warn",
                                             "error", "critical", "off"};

// Camera keys and the sources they apply to (empty: every source).
const std::vector<std::pair<std::string, std::vector<std::string>>> kCameraKeys = {
    {"name", {}},
    {"source", {}},
    {"model", {}},
    {"session", {"replay"}},
    {"session_camera", {"replay"}},
    {"loop", {"replay"}},
    {"realtime", {"replay"}},
    {"device", {"v4l2"}},
    {"camera_id", {"aravis", "libcamera"}},
    {"address", {"aravis"}},
    {"packet_resend", {"aravis"}},
    {"packet_size", {"aravis"}},
    {"pixel_format", {"v4l2", "aravis", "libcamera"}},
    {"width", {"v4l2", "aravis", "libcamera"}},
    {"height", {"v4l2", "aravis", "libcamera"}},
    {"fps", {"v4l2", "aravis", "libcamera"}},
    {"exposure_us", {"v4l2", "aravis", "libcamera"}},
    {"gain_db", {"v4l2", "aravis", "libcamera"}},
    {"white_balance", {"v4l2", "aravis", "libcamera"}},
};

using namespace yaml_text;
using Messages = YamlMessages;
using MapView = YamlMap;
using Reader = YamlReader;

// ---------------------------------------------------------------- the sections' keys
// Each section binds its keys to its fields (core/options_binder.h); the defaults are the
// fields' initial values in core/config.h and the docs are docs/config.md's, shortened.

OptionsBinder WhiteBalanceKeys(WhiteBalanceConfig& wb) {
  OptionsBinder b;
  b.AddEnum("mode", &wb.mode, kWhiteBalanceModeTexts, "device: leave as is; once: auto, then lock; manual")
      .Add("red_gain", &wb.red_gain, "a positive number", "manual: red/green balance ratio")
      .Add("blue_gain", &wb.blue_gain, "a positive number", "manual: blue/green balance ratio")
      .Add("temperature_k", &wb.temperature_k, "a colour temperature in kelvin",
           "manual: colour temperature instead of ratios (V4L2)");
  return b;
}

void ReadWhiteBalance(Reader& r, const YAML::Node& node, const std::string& path,
                      WhiteBalanceConfig& wb) {
  if (node.IsScalar()) {  // shorthand: `white_balance: once`
    r.Mark(Child(path, "mode"), node);
    r.ToEnum(node.Scalar(), kWhiteBalanceModeTexts, Child(path, "mode"), wb.mode);
    return;
  }
  const OptionsBinder keys = WhiteBalanceKeys(wb);
  const MapView view = r.Map(node, path);
  r.Known(view, keys.Keys());
  keys.ReadKeys(r, view);
  const auto given = [&](const char* key) { return view.Find(key) && !r.msg().Failed(Child(path, key)); };
  const bool red = given("red_gain"), blue = given("blue_gain"), kelvin = given("temperature_k");
  if ((red || blue || kelvin) && wb.mode != WhiteBalanceMode::kManual) {
    r.msg().Error(Child(path, red ? "red_gain" : blue ? "blue_gain" : "temperature_k"), "only applies with mode: manual");
  }
  if (kelvin && (red || blue)) {
    r.msg().Error(Child(path, "temperature_k"), "give either the red/blue gains or a colour temperature, not both");
  }
}

// A camera's keys after name and source; which sources take each is kCameraKeys.
OptionsBinder CameraSettingKeys(CameraConfig& cam) {
  OptionsBinder b;
  b.AddPath("model", &cam.model, ".cameramodel; unset: the session's, or none")
      .AddPath("session", &cam.session, "replay: the recorded session's folder")
      .Add("session_camera", &cam.session_camera, "a string", "replay: the camera within the session")
      .Add("loop", &cam.loop, "replay: start over at the end")
      .Add("realtime", &cam.realtime, "replay: paced by the device timestamps")
      .Add("device", &cam.device, "a string", "v4l2: the device, e.g. /dev/video0")
      .Add("camera_id", &cam.camera_id, "a string", "aravis / libcamera: the device id")
      .Add("address", &cam.address, "a string", "aravis: IP address of a GigE Vision camera")
      .Add("packet_resend", &cam.packet_resend, "aravis")
      .Add("packet_size", &cam.packet_size, "a packet size in bytes", "aravis: GigE packet size, 0 = negotiate")
      .Add("pixel_format", &cam.pixel_format, "a string", "yuyv, bayer_rg8...; unset = device default")
      .Add("width", &cam.width, "a width in pixels", "0 = device default")
      .Add("height", &cam.height, "a height in pixels", "0 = device default")
      .Add("fps", &cam.fps, "a positive number", "0 = device default")
      .Add("exposure_us", &cam.exposure_us, "an exposure time in microseconds",
           "unset = keep the device's value, locked")
      .Add("gain_db", &cam.gain_db, "a gain in dB", "unset = keep the device's value, locked")
      .AddRead("white_balance", "device", "device, once, or {mode: manual, ...}",
               [&cam](Reader& r, const MapView& view, const std::string& key) {
                 const YAML::Node* wb = r.Value(view, key);
                 if (wb) ReadWhiteBalance(r, *wb, Child(view.path(), key), cam.white_balance);
                 return wb != nullptr;
               });
  return b;
}

void ReadCamera(Reader& r, const YAML::Node& node, const std::string& path, CameraConfig& cam) {
  const MapView view = r.Map(node, path);
  OptionsBinder identity;
  identity.Add("name", &cam.name, "a string", "unique; the stem of its recorded files")
      .Add("source", &cam.source, "a string", Join(kSources, " | "));
  identity.ReadKeys(r, view);
  // Keys that belong to another source are named as such; others are unknown.
  std::vector<std::string> all;
  for (const auto& [key, sources] : kCameraKeys) all.push_back(key);
  for (const auto& item : view.entries()) {
    const std::string& key = item.first;  // (a structured binding cannot be captured before clang 16)
    const auto it = std::find_if(kCameraKeys.begin(), kCameraKeys.end(),
                                 [&](const auto& k) { return k.first == key; });
    if (it == kCameraKeys.end()) {
      r.msg().Error(Child(path, key), "unknown key" + Suggest(key, all));
    } else if (OneOf(cam.source, kSources) && !it->second.empty() &&
               !OneOf(cam.source, it->second)) {
      r.msg().Error(Child(path, key), "only for source " + Join(it->second, " or ") +
                                          " (this camera's source is " + cam.source + ")");
    }
  }
  CameraSettingKeys(cam).ReadKeys(r, view);
}

OptionsBinder KeyingKeys(KeyingConfig& k) {
  OptionsBinder b;
  b.AddEnum("method", &k.method, kKeyingMethodTexts, "chroma (a green screen) or clean_plate (any background)")
      .Add("training_frames", &k.training_frames, "a number of frames", "empty-enclosure frames to learn from")
      .Add("chroma.low", &k.chroma_low, "a level 0..255", "key difference where alpha starts to fall")
      .Add("chroma.high", &k.chroma_high, "a level 0..255", "... and where it reaches 0")
      .Add("clean_plate.low_sigma", &k.plate_low_sigma, "a number of noise sigmas",
           "difference where alpha starts to rise")
      .Add("clean_plate.high_sigma", &k.plate_high_sigma, "a number of noise sigmas", "... and where it reaches 1")
      .Add("despill.enabled", &k.despill, "remove the green cast from the subject's edges")
      .Add("despill.strength", &k.despill_strength, "a number 0..1", "share of the cast removed")
      .Add("shadow.enabled", &k.shadow, "keep the contact-shadow layer")
      .Add("shadow.min_darkening", &k.shadow_min_darkening, "a fraction 0..1",
           "darkening below which there is no shadow")
      .Add("shadow.max_darkening", &k.shadow_max_darkening, "a fraction 0..1", "darkening that counts as full shadow")
      .Add("shadow.reach_m", &k.shadow_reach_m, "a distance in metres", "shadow kept this far around the foot");
  return b;
}

OptionsBinder EnclosureKeys(EnclosureConfig& e) {
  OptionsBinder b;
  b.Add("wall_height_m", &e.wall_height_m, "a height in metres", "walls occlude the floor behind them up to this")
      .AddRead("floor", "[]", "the floor polygon, [x, y] ground metres in order",
               [&e](Reader& r, const MapView& view, const std::string& key) {
                 const YAML::Node* floor = r.Value(view, key);
                 if (!floor) return false;
                 if (!floor->IsSequence()) {
                   r.msg().Error("enclosure.floor",
                                 "expected a list of [x, y] points in metres, got " + ShapeOf(*floor));
                   return false;
                 }
                 if (floor->size() > GroundPolygon::kMaxVertices) {
                   r.msg().Error("enclosure.floor", std::to_string(floor->size()) +
                                                        " points; a floor polygon has at most " +
                                                        std::to_string(GroundPolygon::kMaxVertices));
                   return false;
                 }
                 std::vector<Eigen::Vector2d> vertices;
                 for (size_t i = 0; i < floor->size(); ++i) {
                   const YAML::Node p = (*floor)[i];
                   const std::string path = Index("enclosure.floor", i);
                   r.Mark(path, p);
                   double x = 0, y = 0;
                   if (!p.IsSequence() || p.size() != 2 || !YAML::convert<double>::decode(p[0], x) ||
                       !YAML::convert<double>::decode(p[1], y)) {
                     r.msg().Error(path, "expected a point [x, y] in metres, got " +
                                             (p.IsSequence() ? "a list of " + std::to_string(p.size())
                                                             : ShapeOf(p)));
                     continue;
                   }
                   vertices.emplace_back(x, y);
                 }
                 e.floor = GroundPolygon(std::move(vertices));
                 return true;
               });
  return b;
}

OptionsBinder PipelineKeys(PipelineConfig& p) {
  OptionsBinder b;
  b.Add("min_area_px", &p.min_area_px, "an area in pixels", "smaller blobs are noise")
      .Add("border_margin_px", &p.border_margin_px, "a number of pixels", "distance to keep from the image border")
      .Add("floor_margin_px", &p.floor_margin_px, "a number of pixels", "floor pixels required around the silhouette")
      .Add("wall_margin_m", &p.wall_margin_m, "a distance in metres", "contact point distance to keep from the walls")
      .Add("still_speed_m_per_s", &p.still_speed_m_per_s, "a speed in m/s", "slower counts as not moving")
      .Add("max_speed_m_per_s", &p.max_speed_m_per_s, "a speed in m/s", "faster starts a new clip")
      .Add("max_still_s", &p.max_still_s, "a duration in seconds", "longer still periods are discarded")
      .Add("min_clip_frames", &p.min_clip_frames, "a number of frames", "shorter clips are discarded")
      .Add("noise_recover_solidity", &p.noise_recover_solidity, "a share from 0 to 1",
           "a subject noise the frame before stays noise below this")
      .Add("noise_thick_px", &p.noise_thick_px, "a distance in pixels", "interior: this far from the matte's edge")
      .Add("noise_min_thick_share", &p.noise_min_thick_share, "a share from 0 to 1", "noise below this interior share")
      .Add("noise_min_solidity", &p.noise_min_solidity, "a share from 0 to 1", "noise below this solidity")
      .Add("noise_min_largest_share", &p.noise_min_largest_share, "a share from 0 to 1",
           "noise when its largest part holds less")
      .Add("noise_min_mean_alpha", &p.noise_min_mean_alpha, "a share from 0 to 1", "noise below this mean alpha")
      .AddRead("px_per_m", "auto", "billboard scale in pixels per metre, or auto",
               [&p](Reader& r, const MapView& view, const std::string& key) {
                 // `auto` (stored as 0) or a positive number of pixels per metre.
                 if (const YAML::Node* n = view.Find(key); n && n->IsScalar() && n->Scalar() == "auto") {
                   p.px_per_m = 0;
                   return true;
                 }
                 double v = 0;
                 if (!r.Number(view, key, v, "auto or a positive number of pixels per metre")) return false;
                 p.px_per_m = v;
                 if (v == 0) r.msg().Error("pipeline.px_per_m", "expected auto or a positive number, got 0");
                 return true;
               })
      .Add("workers", &p.workers, "a number of threads", "OpenCV threads inside a frame's work; 0 = default")
      .Add("queue_frames", &p.queue_frames, "a number of frames", "per-camera queue between capture and pipeline");
  return b;
}

OptionsBinder StorageKeys(StorageConfig& s) {
  OptionsBinder b;
  b.AddRead("bank", Quoted(s.bank), "the sprite bank: a file, or a PostgreSQL server's address",
            [&s](Reader& r, const MapView& view, const std::string& key) {
              // A file (resolved against the config's folder) or a PostgreSQL address, kept as written.
              if (!r.Path(view, key, s.bank)) return false;
              std::string raw;
              r.String(view, key, raw, "a path");
              if (sql::IsPostgresAddress(raw)) s.bank = raw;
              return true;
            })
      .AddPath("recording_dir", &s.recording_dir, "where recorded sessions go")
      .AddEnum("recording", &s.recording, kRecordingModeTexts, "off, all frames, or those that gave a usable sprite")
      .Add("recording_codec", &s.recording_codec, "a string", "ffv1, mjpeg or h264")
      .Add("stop_recording_below_mib", &s.stop_recording_below_mib, "a size in MiB",
           "free disk under which raw recording stops")
      .Add("stop_sprites_below_mib", &s.stop_sprites_below_mib, "a size in MiB",
           "free disk under which sprite storage stops")
      .AddPath("spool_dir", &s.spool_dir, "where clip batches wait while the bank cannot take them")
      .Add("spool_max_mib", &s.spool_max_mib, "a size in MiB", "how much the spool may fill");
  return b;
}

OptionsBinder ControlKeys(ControlConfig& c) {
  OptionsBinder b;
  b.Add("address", &c.address, "an IP address", "where the control server listens")
      .Add("port", &c.port, "a port number 0..65535", "0 = any free port")
      .Add("token", &c.token, "a string", "required when address is not loopback (>= 16 chars)")
      .AddRead("token_file", "\"\"", "a file holding the token",
               [&c](Reader& r, const MapView& view, const std::string& key) {
                 std::string token_file;
                 if (!r.Path(view, key, token_file)) return false;
                 if (view.Find("token")) {
                   r.msg().Error("control.token_file", "give token or token_file, not both");
                   return false;
                 }
                 std::ifstream in(token_file);
                 if (!in) {
                   r.msg().Error("control.token_file",
                                 token_file + ": cannot read the token: " + std::strerror(errno));
                   return false;
                 }
                 std::getline(in, c.token);
                 while (!c.token.empty() && std::isspace(static_cast<unsigned char>(c.token.back())))
                   c.token.pop_back();
                 if (c.token.empty()) r.msg().Error("control.token_file", token_file + ": the file is empty");
                 return true;
               });
  return b;
}

OptionsBinder LoggingKeys(LoggingConfig& l) {
  OptionsBinder b;
  b.Add("level", &l.level, "a log level", Join(kLogLevels, " "))
      .AddRead("components", "{}", "a level per component, e.g. capture.aravis: debug",
               [&l](Reader& r, const MapView& view, const std::string& key) {
                 const YAML::Node* n = r.Value(view, key);
                 if (!n) return false;
                 const MapView c = r.Map(*n, Child(view.path(), key));
                 for (const auto& [component, entry] : c.entries()) {
                   std::string level;
                   if (r.String(c, component, level, "a log level")) l.components[component] = level;
                 }
                 return true;
               });
  return b;
}

// A section read by its binder, when present.
template <typename Config>
OptionsBinder::ReadFn Section(OptionsBinder (*keys)(Config&), Config& config) {
  return [keys, &config](Reader& r, const MapView& view, const std::string& key) {
    const YAML::Node* n = r.Value(view, key);
    if (n) keys(config).Read(r, *n, Child(view.path(), key));
    return n != nullptr;
  };
}

// The whole file.
OptionsBinder StationKeys(StationConfig& cfg) {
  OptionsBinder b;
  b.Add("version", &cfg.version, "a config version number", "the config format's version")
      .AddRead("cameras", "[]", "the cameras, each a mapping",
               [&cfg](Reader& r, const MapView& view, const std::string& key) {
                 const YAML::Node* cams = r.Value(view, key);
                 if (!cams) return false;
                 if (!cams->IsSequence()) {
                   r.msg().Error("cameras", "expected a list of cameras, got " + ShapeOf(*cams));
                   return false;
                 }
                 for (size_t i = 0; i < cams->size(); ++i) {
                   const std::string path = Index("cameras", i);
                   r.Mark(path, (*cams)[i]);
                   cfg.cameras.emplace_back();
                   ReadCamera(r, (*cams)[i], path, cfg.cameras.back());
                 }
                 return true;
               })
      .AddRead("keying", "", "keying.*", Section(KeyingKeys, cfg.keying))
      .AddRead("enclosure", "", "enclosure.*", Section(EnclosureKeys, cfg.enclosure))
      .AddRead("pipeline", "", "pipeline.*", Section(PipelineKeys, cfg.pipeline))
      .AddRead("storage", "", "storage.*", Section(StorageKeys, cfg.storage))
      .AddRead("control", "", "control.*", Section(ControlKeys, cfg.control))
      .AddRead("logging", "", "logging.*", Section(LoggingKeys, cfg.logging));
  return b;
}

// ---------------------------------------------------------------- validation

bool IsIpAddress(const std::string& a) {
  unsigned char buf[16];
  return inet_pton(AF_INET, a.c_str(), buf) == 1 || inet_pton(AF_INET6, a.c_str(), buf) == 1;
}

bool ValidName(const std::string& name) {
  return !name.empty() && std::all_of(name.begin(), name.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.';
  }) && name[0] != '.';
}

class Validator {
 public:
  Validator(Messages& msg, const ConfigOptions& options) : msg_(msg), options_(options) {}

  // Each check reports only when the field has no error from reading already.
  void Check(bool ok, const std::string& path, const std::string& reason) {
    if (!ok && !msg_.Failed(path)) msg_.Error(path, reason);
  }
  void Finite(double v, const std::string& path) {
    Check(std::isfinite(v), path, "expected a finite number, got " + Num(v));
  }
  void Positive(double v, const std::string& path) {
    Check(std::isfinite(v) && v > 0, path, "expected a positive number, got " + Num(v));
  }
  void NonNegative(double v, const std::string& path) {
    Check(std::isfinite(v) && v >= 0, path, "expected a number >= 0, got " + Num(v));
  }
  void Range(double v, double lo, double hi, const std::string& path) {
    Check(std::isfinite(v) && v >= lo && v <= hi, path,
          "expected a number from " + Num(lo) + " to " + Num(hi) + ", got " + Num(v));
  }
  void Enum(const std::string& v, const std::vector<std::string>& options,
            const std::string& path) {
    Check(OneOf(v, options), path, "expected one of " + Join(options) + ", got " + Quoted(v));
  }
  void Exists(const std::string& file, const std::string& path, const std::string& what) {
    if (!options_.check_files || file.empty()) return;
    std::error_code ec;
    Check(fs::exists(file, ec), path, file + ": no such " + what);
  }

  void Camera(CameraConfig& c, const std::string& path) {
    Check(ValidName(c.name), Child(path, "name"),
          c.name.empty() ? "every camera needs a name"
                         : "expected letters, digits, '_', '-' or '.', got " + Quoted(c.name));
    if (c.source.empty()) {
      Check(false, Child(path, "source"),
            "every camera needs a source (one of " + Join(kSources) + ")");
      return;
    }
    Enum(c.source, kSources, Child(path, "source"));
    if (c.source == "replay") {
      Check(!c.session.empty(), Child(path, "session"),
            "a replay camera needs the session folder it replays");
      Exists(c.session.empty() ? "" : (fs::path(c.session) / "session.json").string(),
             Child(path, "session"), "recorded session (session.json)");
      if (c.session_camera.empty()) c.session_camera = c.name;
    } else if (c.source == "v4l2") {
      Check(!c.device.empty(), Child(path, "device"),
            "a v4l2 camera needs its device, e.g. /dev/video0");
    } else if (c.source == "aravis") {
      Check(!c.camera_id.empty() || !c.address.empty(), Child(path, "camera_id"),
            "an aravis camera needs camera_id or address");
      Check(c.camera_id.empty() || c.address.empty(), Child(path, "address"),
            "give camera_id or address, not both");
      if (!c.address.empty()) {
        Check(IsIpAddress(c.address), Child(path, "address"),
              "expected an IP address, got " + Quoted(c.address));
      }
      Check(c.packet_size == 0 || (c.packet_size >= 576 && c.packet_size <= 16384),
            Child(path, "packet_size"),
            "expected 0 (negotiate) or 576..16384 bytes, got " + std::to_string(c.packet_size));
    }
    if (!c.pixel_format.empty()) {
      Check(ParsePixelFormat(c.pixel_format).has_value(), Child(path, "pixel_format"),
            "expected one of mono8, bayer_rg8, bayer_gr8, bayer_gb8, bayer_bg8, rgb8, bgr8, yuyv, "
            "nv12, mjpeg, got " +
                Quoted(c.pixel_format));
    }
    Check(c.width >= 0, Child(path, "width"),
          "expected a width in pixels, got " + std::to_string(c.width));
    Check(c.height >= 0, Child(path, "height"),
          "expected a height in pixels, got " + std::to_string(c.height));
    Check((c.width > 0) == (c.height > 0), Child(path, c.width > 0 ? "height" : "width"),
          "give width and height together");
    // Chroma-subsampled formats carry whole 2-pixel groups: round odd sizes down.
    if ((c.pixel_format == "yuyv" || c.pixel_format == "nv12") && c.width % 2 == 1) {
      msg_.Adjust(Child(path, "width"), std::to_string(c.width) + " is odd, which " +
                                            c.pixel_format + " cannot carry; lowered to " +
                                            std::to_string(c.width - 1));
      --c.width;
    }
    if (c.pixel_format == "nv12" && c.height % 2 == 1) {
      msg_.Adjust(Child(path, "height"), std::to_string(c.height) +
                                             " is odd, which nv12 cannot carry; lowered to " +
                                             std::to_string(c.height - 1));
      --c.height;
    }
    Check(std::isfinite(c.fps) && c.fps >= 0, Child(path, "fps"),
          "expected a positive number, got " + Num(c.fps));
    if (c.exposure_us) Positive(*c.exposure_us, Child(path, "exposure_us"));
    if (c.gain_db) NonNegative(*c.gain_db, Child(path, "gain_db"));
    Positive(c.white_balance.red_gain, Child(path, "white_balance.red_gain"));
    Positive(c.white_balance.blue_gain, Child(path, "white_balance.blue_gain"));
    Check(c.white_balance.temperature_k == 0 ||
              (c.white_balance.temperature_k >= 1500 && c.white_balance.temperature_k <= 15000),
          Child(path, "white_balance.temperature_k"),
          "expected a colour temperature of 1500-15000 K, got " + Num(c.white_balance.temperature_k));
    // How each backend fixes white balance: V4L2 as a colour temperature, GenICam as ratios.
    if (c.white_balance.mode == WhiteBalanceMode::kManual && c.source == "v4l2") {
      Check(c.white_balance.temperature_k > 0, Child(path, "white_balance.temperature_k"),
            "V4L2 devices fix white balance as a colour temperature: give temperature_k");
    }
    if (c.source == "aravis") {
      Check(c.white_balance.temperature_k == 0, Child(path, "white_balance.temperature_k"),
            "GigE Vision cameras fix white balance as red/blue ratios: give red_gain and blue_gain");
    }
    Exists(c.model, Child(path, "model"), "camera model");
  }

  void Run(StationConfig& cfg) {
    Check(cfg.version == kConfigVersion, "version",
          cfg.version > kConfigVersion
              ? "written for a newer SpriteStation (config version " + std::to_string(cfg.version) +
                    "); this one reads version " + std::to_string(kConfigVersion)
              : "expected " + std::to_string(kConfigVersion) + ", got " +
                    std::to_string(cfg.version));
    std::map<std::string, size_t> names;
    for (size_t i = 0; i < cfg.cameras.size(); ++i) {
      const std::string path = Index("cameras", i);
      Camera(cfg.cameras[i], path);
      const auto [it, fresh] = names.emplace(cfg.cameras[i].name, i);
      if (!fresh && !cfg.cameras[i].name.empty()) {
        Check(false, Child(path, "name"),
              Quoted(cfg.cameras[i].name) + " is already the name of " +
                  Index("cameras", it->second));
      }
    }

    KeyingConfig& k = cfg.keying;
    Check(k.training_frames >= 1, "keying.training_frames",
          "expected at least 1 frame, got " + std::to_string(k.training_frames));
    Range(k.chroma_low, 0, 255, "keying.chroma.low");
    Range(k.chroma_high, 0, 255, "keying.chroma.high");
    Check(!(k.chroma_low >= k.chroma_high), "keying.chroma.high",
          "must be above keying.chroma.low (" + Num(k.chroma_low) + "), got " + Num(k.chroma_high));
    NonNegative(k.plate_low_sigma, "keying.clean_plate.low_sigma");
    NonNegative(k.plate_high_sigma, "keying.clean_plate.high_sigma");
    Check(!(k.plate_low_sigma >= k.plate_high_sigma), "keying.clean_plate.high_sigma",
          "must be above keying.clean_plate.low_sigma (" + Num(k.plate_low_sigma) + "), got " +
              Num(k.plate_high_sigma));
    Finite(k.despill_strength, "keying.despill.strength");
    if (std::isfinite(k.despill_strength) && (k.despill_strength < 0 || k.despill_strength > 1)) {
      const double clamped = std::clamp(k.despill_strength, 0.0, 1.0);
      msg_.Adjust("keying.despill.strength",
                  Num(k.despill_strength) + " is outside 0..1; clamped to " + Num(clamped));
      k.despill_strength = clamped;
    }
    Range(k.shadow_min_darkening, 0, 1, "keying.shadow.min_darkening");
    Range(k.shadow_max_darkening, 0, 1, "keying.shadow.max_darkening");
    Check(!(k.shadow_min_darkening >= k.shadow_max_darkening), "keying.shadow.max_darkening",
          "must be above keying.shadow.min_darkening (" + Num(k.shadow_min_darkening) + "), got " +
              Num(k.shadow_max_darkening));
    Positive(k.shadow_reach_m, "keying.shadow.reach_m");

    const auto& floor = cfg.enclosure.floor.vertices();
    if (!floor.empty() && !msg_.Failed("enclosure.floor")) {
      bool points_ok = true;
      for (size_t i = 0; i < floor.size(); ++i)
        points_ok = points_ok && !msg_.Failed(Index("enclosure.floor", i));
      if (points_ok) {
        Check(floor.size() >= 3, "enclosure.floor",
              "a floor polygon needs at least 3 points, got " + std::to_string(floor.size()));
        if (floor.size() >= 3) {
          Check(
              cfg.enclosure.floor.IsSimple(), "enclosure.floor",
              "the polygon crosses itself, repeats a point, has a non-finite point or has no area "
              "(list the corners in order around the floor)");
        }
      }
    }
    NonNegative(cfg.enclosure.wall_height_m, "enclosure.wall_height_m");

    PipelineConfig& p = cfg.pipeline;
    Check(p.min_area_px >= 1, "pipeline.min_area_px",
          "expected at least 1 pixel, got " + std::to_string(p.min_area_px));
    Check(p.border_margin_px >= 0, "pipeline.border_margin_px",
          "expected a number >= 0, got " + std::to_string(p.border_margin_px));
    Check(p.floor_margin_px >= 0, "pipeline.floor_margin_px",
          "expected a number >= 0, got " + std::to_string(p.floor_margin_px));
    NonNegative(p.wall_margin_m, "pipeline.wall_margin_m");
    Positive(p.still_speed_m_per_s, "pipeline.still_speed_m_per_s");
    Positive(p.max_speed_m_per_s, "pipeline.max_speed_m_per_s");
    Positive(p.max_still_s, "pipeline.max_still_s");
    Check(p.min_clip_frames >= 1, "pipeline.min_clip_frames",
          "expected at least 1 frame, got " + std::to_string(p.min_clip_frames));
    NonNegative(p.noise_thick_px, "pipeline.noise_thick_px");
    for (const auto& [v, key] : {std::pair{p.noise_recover_solidity, "noise_recover_solidity"},
                                 std::pair{p.noise_min_thick_share, "noise_min_thick_share"},
                                 std::pair{p.noise_min_solidity, "noise_min_solidity"},
                                 std::pair{p.noise_min_largest_share, "noise_min_largest_share"},
                                 std::pair{p.noise_min_mean_alpha, "noise_min_mean_alpha"}}) {
      Check(std::isfinite(v) && v >= 0 && v <= 1, std::string("pipeline.") + key,
            "expected a share from 0 to 1 (0 turns the test off), got " + Num(v));
    }
    Check(p.px_per_m == 0 || (std::isfinite(p.px_per_m) && p.px_per_m > 0), "pipeline.px_per_m",
          "expected auto or a positive number, got " + Num(p.px_per_m));
    Check(p.workers >= 0, "pipeline.workers",
          "expected 0 (one per core) or more, got " + std::to_string(p.workers));
    Check(p.queue_frames >= 1, "pipeline.queue_frames",
          "expected at least 1 frame, got " + std::to_string(p.queue_frames));
    constexpr int kMaxQueue = 1024;
    if (p.queue_frames > kMaxQueue) {
      msg_.Adjust("pipeline.queue_frames", std::to_string(p.queue_frames) +
                                               " would hold too many frames in memory; "
                                               "lowered to " +
                                               std::to_string(kMaxQueue));
      p.queue_frames = kMaxQueue;
    }

    StorageConfig& s = cfg.storage;
    Check(!s.bank.empty(), "storage.bank", "expected a path");
    Check(!s.recording_dir.empty(), "storage.recording_dir", "expected a path");
    {
      std::vector<std::string> codecs;
      for (const RecordingCodec& c : RecordingCodecs()) codecs.push_back(c.name);
      Enum(s.recording_codec, codecs, "storage.recording_codec");
    }
    Check(s.stop_recording_below_mib >= 0, "storage.stop_recording_below_mib",
          "expected a size >= 0, got " + std::to_string(s.stop_recording_below_mib));
    Check(s.spool_max_mib >= 1, "storage.spool_max_mib", "expected a size >= 1, got " + std::to_string(s.spool_max_mib));
    Check(s.stop_sprites_below_mib >= 0, "storage.stop_sprites_below_mib",
          "expected a size >= 0, got " + std::to_string(s.stop_sprites_below_mib));
    // Raw recording must stop first: its low-water mark is never below the sprites' one.
    if (s.stop_recording_below_mib < s.stop_sprites_below_mib && s.stop_recording_below_mib >= 0 &&
        !msg_.Failed("storage.stop_recording_below_mib") &&
        !msg_.Failed("storage.stop_sprites_below_mib")) {
      msg_.Adjust("storage.stop_recording_below_mib",
                  std::to_string(s.stop_recording_below_mib) +
                      " is below stop_sprites_below_mib; raised to " +
                      std::to_string(s.stop_sprites_below_mib) +
                      " so that raw recording stops before sprite storage");
      s.stop_recording_below_mib = s.stop_sprites_below_mib;
    }

    ControlConfig& c = cfg.control;
    Check(c.address == "localhost" || IsIpAddress(c.address), "control.address",
          "expected an IP address (or localhost), got " + Quoted(c.address));
    Check(c.port >= 0 && c.port <= 65535, "control.port",
          "expected a port number 0..65535, got " + std::to_string(c.port));
    if (!c.token.empty()) {
      Check(c.token.size() >= 16, "control.token",
            "too short: use at least 16 characters (got " + std::to_string(c.token.size()) + ")");
    } else if (!IsLoopbackAddress(c.address) && !msg_.Failed("control.address")) {
      msg_.Error("control.token",
                 "required when control.address (" + c.address +
                     ") is not loopback; set token or token_file",
                 "control.address");
    }

    LoggingConfig& l = cfg.logging;
    Enum(l.level, kLogLevels, "logging.level");
    for (const auto& [component, level] : l.components)
      Enum(level, kLogLevels, "logging.components." + component);
  }

 private:
  Messages& msg_;
  const ConfigOptions& options_;
};

ConfigReport MakeReport(const Messages& msg) {
  ConfigReport report;
  report.errors = msg.errors;
  report.adjustments = msg.adjustments;
  report.status = !msg.errors.empty()        ? ConfigStatus::kInvalid
                  : !msg.adjustments.empty() ? ConfigStatus::kAdjusted
                                             : ConfigStatus::kValid;
  return report;
}

// Throws on kInvalid; logs adjustments; hands the report back.
void Conclude(const ConfigReport& report, ConfigReport* out) {
  if (out) *out = report;
  if (report.status == ConfigStatus::kInvalid) throw InputError(Join(report.errors, "\n"));
  for (const auto& a : report.adjustments) Log("core.config")->warn("adjusted: {}", a);
}

}  // namespace

std::string ConfigReport::Summary() const {
  std::vector<std::string> lines = errors;
  for (const auto& a : adjustments) lines.push_back("adjusted: " + a);
  return Join(lines, "\n");
}

bool IsLoopbackAddress(const std::string& address) {
  if (address == "localhost" || address == "::1") return true;
  unsigned char buf[16];
  if (inet_pton(AF_INET, address.c_str(), buf) == 1) return buf[0] == 127;
  if (inet_pton(AF_INET6, address.c_str(), buf) == 1) {
    // ::ffff:127.x.y.z (IPv4-mapped loopback)
    static const unsigned char prefix[12] = {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0xff, 0xff};
    return std::equal(prefix, prefix + 12, buf) && buf[12] == 127;
  }
  return false;
}

ConfigReport ValidateStationConfig(StationConfig& config, const std::string& origin,
                                   const std::map<std::string, int>& lines,
                                   const ConfigOptions& options) {
  Messages msg(origin, lines);
  Validator(msg, options).Run(config);
  return MakeReport(msg);
}

StationConfig ParseStationConfig(const std::string& yaml, const std::string& origin,
                                 const std::string& base_dir, ConfigReport* report,
                                 const ConfigOptions& options) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml);
  } catch (const YAML::Exception& e) {
    const std::string where =
        e.mark.is_null() ? origin : origin + ":" + std::to_string(e.mark.line + 1);
    throw InputError(where, "not valid YAML: " + e.msg);
  }
  if (root.IsNull()) {
    throw InputError(origin,
                     "the config is empty (expected sections such as cameras, enclosure, storage)");
  }
  std::map<std::string, int> lines;
  Messages msg(origin, lines);
  Reader r(msg, lines, base_dir);

  StationConfig cfg;
  cfg.storage.bank = r.Resolve("station.bank");
  cfg.storage.recording_dir = r.Resolve("recordings");
  cfg.storage.spool_dir = r.Resolve("spool");
  StationKeys(cfg).Read(r, root, "");

  Validator(msg, options).Run(cfg);
  Conclude(MakeReport(msg), report);
  return cfg;
}

StationConfig LoadStationConfig(const std::string& path, ConfigReport* report,
                                const ConfigOptions& options) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) throw InputError(path, "is a directory, not a config file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, std::string("cannot open the config: ") + std::strerror(errno));
  std::ostringstream text;
  text << in.rdbuf();
  const fs::path base = fs::absolute(fs::path(path), ec).parent_path();
  return ParseStationConfig(text.str(), path, base.string(), report, options);
}

const char* ToText(WhiteBalanceMode mode) { return TextOf(mode, kWhiteBalanceModeTexts); }
const char* ToText(KeyingMethod method) { return TextOf(method, kKeyingMethodTexts); }
const char* ToText(RecordingMode mode) { return TextOf(mode, kRecordingModeTexts); }

}  // namespace ss
