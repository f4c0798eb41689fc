// The station config's values and cross-field rules: Valid / Adjusted / Invalid with the reason
// (config/station_config.h, ValidateStationConfig).
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <tuple>
#include <utility>

#include "capture/camera_backend.h"
#include "config/config_detail.h"
#include "core/bank_schema.h"
#include "core/frame.h"
#include "core/ip_address.h"
#include "core/option_checks.h"
#include "core/recording_codecs.h"
#include "pipeline/key/keying_keys.h"

namespace ss {
namespace config_detail {
namespace {

namespace fs = std::filesystem;
using namespace yaml_text;
using Messages = YamlMessages;

// A camera's name: it names folders, files and URLs, and is shown in every message about it.
constexpr size_t kMaxNameLength = 64;
// The frames of the empty enclosure a camera holds while it learns (BGR, its full size): each
// camera's set is held at once, in memory, before the keyer is made.
constexpr int64_t kTrainingSetBytes = int64_t{1} << 30;  // 1 GiB per camera
constexpr int kMaxTrainingFrames = 1000;                 // whatever the size
constexpr int kUnsetWidth = 1920, kUnsetHeight = 1080;   // a camera of the device's default size

bool ValidName(const std::string& name) {
  return !name.empty() && name.size() <= kMaxNameLength &&
         std::all_of(name.begin(), name.end(),
                     [](char c) {
                       return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' ||
                              c == '.';
                     }) &&
         name[0] != '.';
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
  void Enum(const std::string& v, const std::vector<std::string>& options,
            const std::string& path) {
    Check(OneOf(v, options), path, "expected one of " + Join(options) + ", got " + Quoted(v));
  }
  // An options struct's own rules (its IsValid's "field: reason" lines), each at its key in
  // `block`: the component states its ranges once, and the config reports them by key.
  void Rules(bool ok, const std::string& why, const std::string& block) {
    if (ok) return;
    for (const auto& [field, reason] : OptionProblems::Split(why))
      Check(false, field.empty() ? block : Child(block, field), reason);
  }
  void Exists(const std::string& file, const std::string& path, const std::string& what) {
    if (!options_.check_files || file.empty()) return;
    std::error_code ec;
    Check(fs::exists(file, ec), path, file + ": no such " + what);
  }

  void Camera(CameraConfig& c, const std::string& path) {
    Check(ValidName(c.name), Child(path, "name"),
          c.name.empty() ? "every camera needs a name"
          : c.name.size() > kMaxNameLength
              ? "expected a name of at most " + std::to_string(kMaxNameLength) +
                    " characters, got " + std::to_string(c.name.size())
              : "expected letters, digits, '_', '-' or '.', got " + Quoted(c.name));
    if (c.source.empty()) {
      Check(false, Child(path, "source"),
            "every camera needs a source (one of " + Join(CameraBackendNames()) + ")");
      return;
    }
    // The backend's own rules on its keys (capture/camera_backend.h), each at its key.
    const CameraBackend* backend = FindCameraBackend(c.source);
    Enum(c.source, CameraBackendNames(), Child(path, "source"));
    if (std::string why; backend != nullptr && backend->check)
      Rules(backend->check(c, &why), why, path);
    if (backend != nullptr && backend->files) {
      for (const CameraFile& f : backend->files(c)) Exists(f.file, Child(path, f.key), f.what);
    }
    if (!c.pixel_format.empty()) {
      Check(ParsePixelFormat(c.pixel_format).has_value(), Child(path, "pixel_format"),
            "expected one of mono8, bayer_rg8, bayer_gr8, bayer_gb8, bayer_bg8, rgb8, bgr8, yuyv, "
            "nv12, mjpeg, got " +
                Quoted(c.pixel_format));
    }
    // The bounds its keys are bound with (config_keys.cc): width, height, fps, exposure, gain,
    // the white balance's gains.
    CameraSettingKeys(c).CheckRules(msg_, path);
    WhiteBalanceKeys(c.white_balance).CheckRules(msg_, Child(path, "white_balance"));
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
    Check(
        c.white_balance.temperature_k == 0 ||
            (c.white_balance.temperature_k >= 1500 && c.white_balance.temperature_k <= 15000),
        Child(path, "white_balance.temperature_k"),
        "expected a colour temperature of 1500-15000 K, got " + Num(c.white_balance.temperature_k));
    Exists(c.model, Child(path, "model"), "camera model");
  }

  void Keying(KeyingConfig& k, const std::vector<CameraConfig>& cameras) {
    CheckKeying(k, msg_, "keying");  // the section's own rules (pipeline/key/keying_keys.h)
    // The training set must fit in memory (the daemon failed every frame with bad_alloc): the
    // largest camera's frames against the budget; a camera of unset size counts as 1920x1080.
    int width = cameras.empty() ? kUnsetWidth : 0, height = cameras.empty() ? kUnsetHeight : 0;
    for (const CameraConfig& c : cameras) {
      const int w = c.width > 0 ? c.width : kUnsetWidth, h = c.height > 0 ? c.height : kUnsetHeight;
      if (int64_t{w} * h > int64_t{width} * height) std::tie(width, height) = std::pair{w, h};
    }
    const int64_t frame_bytes = int64_t{width} * height * 3;
    const int64_t most =
        std::clamp<int64_t>(kTrainingSetBytes / frame_bytes, 1, kMaxTrainingFrames);
    if (k.training_frames > most) {
      char gib[32];
      std::snprintf(gib, sizeof gib, "%.1f",
                    static_cast<double>(k.training_frames) * static_cast<double>(frame_bytes) /
                        static_cast<double>(int64_t{1} << 30));
      Check(false, "keying.training_frames",
            "expected at most " + std::to_string(most) +
                " frames: " + std::to_string(k.training_frames) + " frames of " +
                std::to_string(width) + "x" + std::to_string(height) + " take " + gib +
                " GiB, and a camera's training set may hold 1 GiB (" +
                std::to_string(kMaxTrainingFrames) + " frames at most)");
    }
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

    if (cfg.pipeline.keying) Keying(*cfg.pipeline.keying, cfg.cameras);

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
    EnclosureKeys(cfg).CheckRules(msg_, "enclosure");  // the bounds its keys are bound with

    CameraPipelineOptions& p = cfg.pipeline;
    PipelineKeys(p).CheckRules(msg_, "pipeline");  // the bounds its keys are bound with
    const double ratio = p.side_by_side.min_width_ratio;
    Check(std::isfinite(ratio) && (ratio == 0 || ratio >= 1), "pipeline.merged_min_width_ratio",
          "expected 0 (off) or a ratio of at least 1, got " + Num(ratio));
    // `auto` (0) is the config's own: the rectifier needs the scale chosen.
    const double px_per_m = p.rectify.px_per_m;
    Check(px_per_m == 0 || (std::isfinite(px_per_m) && px_per_m > 0), "pipeline.px_per_m",
          "expected auto or a positive number, got " + Num(px_per_m));
    constexpr int kMaxQueue = 1024;
    if (p.queue_frames > kMaxQueue) {
      msg_.Adjust("pipeline.queue_frames", std::to_string(p.queue_frames) +
                                               " would hold too many frames in memory; "
                                               "lowered to " +
                                               std::to_string(kMaxQueue));
      p.queue_frames = kMaxQueue;
    }
    // The stages' own rules (CameraPipelineOptions::IsValid) on what the keys above set: each
    // bound key's bounds are its binding's, so a problem here is a rule no binding says (a defect
    // of the bindings, not of the file), still refused, at the block.
    const bool pipeline_failed =
        std::any_of(msg_.failed.begin(), msg_.failed.end(), [](const std::string& f) {
          return f.rfind("pipeline.", 0) == 0 || f == "enclosure.wall_height_m";
        });
    if (std::string why; !pipeline_failed && !p.IsValid(&why)) Check(false, "pipeline", why);

    StorageConfig& s = cfg.storage;
    Check(!s.bank.empty(), "storage.bank", "expected a path");
    // A folder or a device: the daemon would refuse to start, with these words.
    if (options_.check_files && !s.bank.empty()) {
      const std::string problem = BankPathProblem(s.bank);
      Check(problem.empty(), "storage.bank", s.bank + ": " + problem);
    }
    Check(!s.recording_dir.empty(), "storage.recording_dir", "expected a path");
    {
      std::vector<std::string> codecs;
      for (const RecordingCodec& c : RecordingCodecs()) codecs.push_back(c.name);
      Enum(s.recording_codec, codecs, "storage.recording_codec");
    }
    StorageKeys(s).CheckRules(msg_, "storage");  // the bounds its keys are bound with
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

    TransitionsKeys(cfg.transitions).CheckRules(msg_, "transitions");  // its keys' bounds

    ControlConfig& c = cfg.control;
    Check(c.address == "localhost" || IsIpAddress(c.address), "control.address",
          "expected an IP address (or localhost), got " + Quoted(c.address));
    ControlKeys(c).CheckRules(msg_, "control");  // the bounds its keys are bound with
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

}  // namespace

void Validate(StationConfig& cfg, YamlMessages& msg, const ConfigOptions& options) {
  Validator(msg, options).Run(cfg);
}

ConfigReport MakeReport(const Messages& msg) {
  ConfigReport report;
  report.errors = msg.errors;
  report.adjustments = msg.adjustments;
  report.status = !msg.errors.empty()        ? ConfigStatus::kInvalid
                  : !msg.adjustments.empty() ? ConfigStatus::kAdjusted
                                             : ConfigStatus::kValid;
  return report;
}

}  // namespace config_detail

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
  YamlMessages msg(origin, lines);
  config_detail::Validate(config, msg, options);
  return config_detail::MakeReport(msg);
}

}  // namespace ss
