// The station config's keys, each bound to its field (core/options_binder.h). The defaults are
// the fields' initial values in config/station_config.h; docs/config.md is the contract.
#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <map>

#include "capture/camera_backend.h"
#include "config/config_detail.h"
#include "core/posix.h"
#include "core/sql_postgres.h"

namespace ss::config_detail {

const std::vector<std::string> kLogLevels = {"trace", "debug",    "info", "warn",
                                             "error", "critical", "off"};

namespace {

using namespace yaml_text;
using Messages = YamlMessages;
using MapView = YamlMap;
using Reader = YamlReader;

// The docs are docs/config.md's, shortened.

OptionsBinder WhiteBalanceKeys(WhiteBalanceConfig& wb) {
  OptionsBinder b;
  b.AddEnum("mode", &wb.mode, kWhiteBalanceModeTexts,
            "device: leave as is; once: auto, then lock; manual")
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
  const auto given = [&](const char* key) {
    return view.Find(key) && !r.msg().Failed(Child(path, key));
  };
  const bool red = given("red_gain"), blue = given("blue_gain"), kelvin = given("temperature_k");
  if ((red || blue || kelvin) && wb.mode != WhiteBalanceMode::kManual) {
    r.msg().Error(Child(path, red    ? "red_gain"
                              : blue ? "blue_gain"
                                     : "temperature_k"),
                  "only applies with mode: manual");
  }
  if (kelvin && (red || blue)) {
    r.msg().Error(Child(path, "temperature_k"),
                  "give either the red/blue gains or a colour temperature, not both");
  }
}

// The settings of a device, which every backend of one takes (CameraBackend::device_settings).
void DeviceSettingKeys(OptionsBinder& b, CameraConfig& cam) {
  b.Add("pixel_format", &cam.pixel_format, "a string", "yuyv, bayer_rg8...; unset = device default")
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
}

// A camera's keys after name and source: its model, and what its backend takes (the device
// settings, and the keys the backend binds itself, capture/camera_backend.h).
OptionsBinder CameraSettingKeys(CameraConfig& cam) {
  OptionsBinder b;
  b.AddPath("model", &cam.model, ".cameramodel; unset: the session's, or none");
  const CameraBackend* backend = FindCameraBackend(cam.source);
  if (backend == nullptr) return b;
  if (backend->device_settings) DeviceSettingKeys(b, cam);
  if (backend->keys) backend->keys(b, cam);
  return b;
}

// Every camera key after name and source, with the backends that take it (none: every one).
std::map<std::string, std::vector<std::string>> CameraKeySources() {
  std::map<std::string, std::vector<std::string>> sources;
  CameraConfig scratch;
  for (const CameraBackend* backend : CameraBackends()) {
    scratch.source = backend->name;
    for (const std::string& key : CameraSettingKeys(scratch).Keys())
      sources[key].push_back(backend->name);
  }
  sources["model"].clear();
  return sources;
}

void ReadCamera(Reader& r, const YAML::Node& node, const std::string& path, CameraConfig& cam) {
  const MapView view = r.Map(node, path);
  OptionsBinder identity;
  identity.Add("name", &cam.name, "a string", "unique; the stem of its recorded files")
      .Add("source", &cam.source, "a string",
           "the camera backend: " + Join(CameraBackendNames(), " | "));
  identity.ReadKeys(r, view);
  // Keys that belong to another source are named as such; others are unknown.
  const auto sources = CameraKeySources();
  std::vector<std::string> all = {"name", "source"};
  for (const auto& [key, backends] : sources) all.push_back(key);
  const bool known_source = FindCameraBackend(cam.source) != nullptr;
  for (const auto& item : view.entries()) {
    const std::string& key = item.first;
    const auto it = sources.find(key);
    if (it == sources.end()) {
      if (!OneOf(key, {"name", "source"}))
        r.msg().Error(Child(path, key), "unknown key" + Suggest(key, all));
    } else if (known_source && !it->second.empty() && !OneOf(cam.source, it->second)) {
      r.msg().Error(Child(path, key), "only for source " + Join(it->second, " or ") +
                                          " (this camera's source is " + cam.source + ")");
    }
  }
  CameraSettingKeys(cam).ReadKeys(r, view);
}

OptionsBinder KeyingKeys(KeyingConfig& k) {
  OptionsBinder b;
  b.AddEnum("method", &k.method, kKeyingMethodTexts,
            "chroma (a green screen) or clean_plate (any background)")
      .Add("training_frames", &k.training_frames, "a number of frames",
           "empty-enclosure frames to learn from")
      .Add("chroma.low", &k.chroma.key_low_levels, "a level 0..255",
           "key difference where alpha starts to fall")
      .Add("chroma.high", &k.chroma.key_high_levels, "a level 0..255", "... and where it reaches 0")
      .Add("clean_plate.low_sigma", &k.clean_plate.low_sigma, "a number of noise sigmas",
           "difference where alpha starts to rise")
      .Add("clean_plate.high_sigma", &k.clean_plate.high_sigma, "a number of noise sigmas",
           "... and where it reaches 1")
      .Add("despill.enabled", &k.despill.enabled, "remove the green cast from the subject's edges")
      .Add("despill.strength", &k.despill.strength, "a number 0..1", "share of the cast removed")
      .Add("shadow.enabled", &k.shadow.enabled, "keep the contact-shadow layer")
      .Add("shadow.min_darkening", &k.shadow.min_darkening, "a fraction 0..1",
           "darkening below which there is no shadow")
      .Add("shadow.max_darkening", &k.shadow.max_darkening, "a fraction 0..1",
           "darkening that counts as full shadow")
      .Add("shadow.reach_m", &k.shadow_reach_m, "a distance in metres",
           "shadow kept this far around the foot");
  return b;
}

// wall_height_m tunes the pipeline's usability tests: bound to their field.
OptionsBinder EnclosureKeys(StationConfig& cfg) {
  EnclosureConfig& e = cfg.enclosure;
  OptionsBinder b;
  b.Add("wall_height_m", &cfg.pipeline.usability.wall_height_m, "a height in metres",
        "walls occlude the floor behind them up to this")
      .AddRead(
          "floor", "[]", "the floor polygon, [x, y] ground metres in order",
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

// Each key bound straight to the stage option it sets (pipeline/run/camera_pipeline.h).
OptionsBinder PipelineKeys(CameraPipelineOptions& p) {
  OptionsBinder b;
  b.Add("min_area_px", &p.extract.min_area, "an area in pixels", "smaller blobs are noise")
      .Add("border_margin_px", &p.usability.border_margin_px, "a number of pixels",
           "distance to keep from the image border")
      .Add("floor_margin_px", &p.usability.floor_margin_px, "a number of pixels",
           "floor pixels required around the silhouette")
      .Add("wall_margin_m", &p.usability.wall_margin_m, "a distance in metres",
           "contact point distance to keep from the walls")
      .Add("max_view_angle_deg", &p.usability.max_view_angle_deg, "an angle in degrees",
           "steeper views of a contact point are refused (view_too_steep)")
      .Add("still_speed_m_per_s", &p.still_speed_m_per_s, "a speed in m/s",
           "slower counts as not moving")
      .Add("max_speed_m_per_s", &p.track.max_speed_m_per_s, "a speed in m/s",
           "faster starts a new clip")
      .Add("max_still_s", &p.max_still_s, "a duration in seconds",
           "longer still periods are discarded")
      .Add("min_clip_frames", &p.batch.min_clip_frames, "a number of frames",
           "shorter clips are discarded")
      .Add("noise_recover_solidity", &p.noise.recover_solidity, "a share from 0 to 1",
           "a subject noise the frame before stays noise below this")
      .Add("noise_thick_px", &p.noise.thick_px, "a distance in pixels",
           "interior: this far from the matte's edge")
      .Add("noise_min_thick_share", &p.noise.min_thick_share, "a share from 0 to 1",
           "noise below this interior share")
      .Add("noise_min_solidity", &p.noise.min_solidity, "a share from 0 to 1",
           "noise below this solidity")
      .Add("noise_min_largest_share", &p.noise.min_largest_share, "a share from 0 to 1",
           "noise when its largest part holds less")
      .Add("noise_min_mean_alpha", &p.noise.min_mean_alpha, "a share from 0 to 1",
           "noise below this mean alpha")
      .Add("merged_min_width_ratio", &p.side_by_side.min_width_ratio, "0 or a ratio of at least 1",
           "two side by side when split and this many times one subject's width")
      .AddRead("px_per_m", "auto", "billboard scale in pixels per metre, or auto",
               [&p](Reader& r, const MapView& view, const std::string& key) {
                 // `auto` (stored as 0) or a positive number of pixels per metre.
                 if (const YAML::Node* n = view.Find(key);
                     n && n->IsScalar() && n->Scalar() == "auto") {
                   p.rectify.px_per_m = 0;
                   return true;
                 }
                 double v = 0;
                 if (!r.Number(view, key, v, "auto or a positive number of pixels per metre"))
                   return false;
                 p.rectify.px_per_m = v;
                 if (v == 0)
                   r.msg().Error("pipeline.px_per_m", "expected auto or a positive number, got 0");
                 return true;
               })
      .Add("workers", &p.workers, "a number of threads",
           "OpenCV threads inside a frame's work; 0 = default")
      .Add("queue_frames", &p.queue_frames, "a number of frames",
           "per-camera queue between capture and pipeline");
  return b;
}

OptionsBinder TransitionsKeys(TransitionsConfig& t) {
  OptionsBinder b;
  b.Add("include_merged", &t.include_merged,
        "sprites tagged merged (two subjects in one blob) take part in transitions");
  return b;
}

OptionsBinder StorageKeys(StorageConfig& s) {
  OptionsBinder b;
  b.AddRead("bank", Quoted(s.bank), "the sprite bank: a file, or a PostgreSQL server's address",
            [&s](Reader& r, const MapView& view, const std::string& key) {
              // A file (resolved against the config's folder) or a PostgreSQL address, kept as
              // written.
              if (!r.Path(view, key, s.bank)) return false;
              std::string raw;
              r.String(view, key, raw, "a path");
              if (sql::IsPostgresAddress(raw)) s.bank = raw;
              return true;
            })
      .AddPath("recording_dir", &s.recording_dir, "where recorded sessions go")
      .AddEnum("recording", &s.recording, kRecordingModeTexts,
               "off, all frames, or those that gave a usable sprite")
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
      .AddRead(
          "token_file", "\"\"", "a file holding the token",
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
                            token_file + ": cannot read the token: " + ErrnoText(errno));
              return false;
            }
            std::getline(in, c.token);
            while (!c.token.empty() && std::isspace(static_cast<unsigned char>(c.token.back())))
              c.token.pop_back();
            if (c.token.empty())
              r.msg().Error("control.token_file", token_file + ": the file is empty");
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
                   if (r.String(c, component, level, "a log level"))
                     l.components[component] = level;
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

}  // namespace

// The whole file.
OptionsBinder StationKeys(StationConfig& cfg) {
  if (!cfg.pipeline.keying) cfg.pipeline.keying.emplace();  // the keying section's home
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
                 if (cams->size() == 0) {  // replay and ingest would do nothing and exit 0
                   r.msg().Error("cameras", "expected at least one camera");
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
      .AddRead("keying", "", "keying.*", Section(KeyingKeys, *cfg.pipeline.keying))
      .AddRead("enclosure", "", "enclosure.*", Section(EnclosureKeys, cfg))
      .AddRead("pipeline", "", "pipeline.*", Section(PipelineKeys, cfg.pipeline))
      .AddRead("transitions", "", "transitions.*", Section(TransitionsKeys, cfg.transitions))
      .AddRead("storage", "", "storage.*", Section(StorageKeys, cfg.storage))
      .AddRead("control", "", "control.*", Section(ControlKeys, cfg.control))
      .AddRead("logging", "", "logging.*", Section(LoggingKeys, cfg.logging));
  return b;
}

}  // namespace ss::config_detail
