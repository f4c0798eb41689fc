// The station config's keys, each bound to its field (core/options_binder.h), with its type and
// doc. The defaults are the fields' initial values in config/station_config.h. docs/config.md's
// key tables are made from these bindings (`spritestation config keys --markdown`, KeyBlocks
// below); a test fails when the doc is stale.
#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "capture/camera_backend.h"
#include "config/config_detail.h"
#include "core/error.h"
#include "core/posix.h"
#include "core/recording_codecs.h"
#include "core/sql_postgres.h"

namespace ss::config_detail {

const std::vector<std::string> kLogLevels = {"trace", "debug",    "info", "warn",
                                             "error", "critical", "off"};

namespace {

using namespace yaml_text;
using Messages = YamlMessages;
using MapView = YamlMap;
using Reader = YamlReader;

// The value of `key` when it is a list; null when absent or not a list (reported: "expected
// EXPECTED, got ...").
const YAML::Node* ListValue(Reader& r, const MapView& view, const std::string& key,
                            const std::string& expected) {
  const YAML::Node* n = r.Value(view, key);
  if (n && !n->IsSequence()) {
    r.msg().Error(Child(view.path(), key), "expected " + expected + ", got " + ShapeOf(*n));
    return nullptr;
  }
  return n;
}

}  // namespace

OptionsBinder WhiteBalanceKeys(WhiteBalanceConfig& wb) {
  OptionsBinder b;
  b.AddEnum("mode", &wb.mode, kWhiteBalanceModeTexts,
            "`device`: leave the device's setting; `once`: run the device's auto white balance "
            "once at start, then lock it; `manual`: set the gains below and lock")
      .Add("red_gain", &wb.red_gain, "a positive number",
           "red/green balance ratio (only with `mode: manual`)")
      .Rule(Positive())
      .Add("blue_gain", &wb.blue_gain, "a positive number",
           "blue/green balance ratio (only with `mode: manual`)")
      .Rule(Positive())
      .Add("temperature_k", &wb.temperature_k, "a colour temperature in kelvin",
           "colour temperature in kelvin instead of the ratios (only with `mode: manual`)")
      .Type("number 1500..15000")
      .Default("unset");
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
  b.Add("pixel_format", &cam.pixel_format, "a string",
        "`mono8`, `bayer_rg8`, `bayer_gr8`, `bayer_gb8`, `bayer_bg8`, `rgb8`, `bgr8`, `yuyv`, "
        "`nv12`, `mjpeg`")
      .Default("device default")
      .Add("width", &cam.width, "a width in pixels",
           "image width in pixels, `0` the device's; give `width` and `height` both or neither; "
           "a yuyv or nv12 width must be even (an odd one is lowered by one, adjusted)")
      .Rule(AtLeast(0))
      .Default("device default")
      .Add("height", &cam.height, "a height in pixels",
           "image height in pixels, `0` the device's; an nv12 height must be even (adjusted)")
      .Rule(AtLeast(0))
      .Default("device default")
      .Add("fps", &cam.fps, "a positive number", "frames per second, `0` the device's")
      .Rule(AtLeast(0))
      .Default("device default")
      .Add("exposure_us", &cam.exposure_us, "a positive number",
           "fixed exposure time in µs. Exposure is always locked: a keyer needs it fixed")
      .Rule(Positive())
      .Default("the device's current value")
      .Add("gain_db", &cam.gain_db, "a number >= 0",
           "fixed analogue gain, locked. Aravis: dB (GenICam `Gain`); libcamera: converted to "
           "`AnalogueGain` (10^(dB/20)); V4L2: `V4L2_CID_GAIN` has no standard unit, so the "
           "number is written as the driver's own gain value, rounded")
      .Rule(AtLeast(0))
      .Default("the device's current value")
      .AddRead("white_balance", "device",
               "a mode (`white_balance: once`) or a mapping ([white_balance](#white_balance))",
               [&cam](Reader& r, const MapView& view, const std::string& key) {
                 const YAML::Node* wb = r.Value(view, key);
                 if (wb) ReadWhiteBalance(r, *wb, Child(view.path(), key), cam.white_balance);
                 return wb != nullptr;
               })
      .Type("mode or mapping");
}

// A camera's keys after name and source: its model, and what its backend takes (the device
// settings, and the keys the backend binds itself, capture/camera_backend.h).
OptionsBinder CameraSettingKeys(CameraConfig& cam) {
  OptionsBinder b;
  b.AddPath("model", &cam.model,
            "its mrcal `.cameramodel` (intrinsics and `cam_from_ground`); empty: a replay camera "
            "uses its session's model; a live camera without a model cannot rectify sprites");
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

// The two keys every camera has.
OptionsBinder CameraIdentityKeys(CameraConfig& cam) {
  OptionsBinder b;
  b.Add("name", &cam.name, "a string",
        "unique; letters, digits, `_`, `-`, `.`, at most 64 characters; the stem of the "
        "camera's recorded files and its name in the bank and the API")
      .Default("required")
      .Add("source", &cam.source, "a string", "the camera backend")
      .Type(OptionsBinder::Choices(CameraBackendNames()))
      .Default("required");
  return b;
}

void ReadCamera(Reader& r, const YAML::Node& node, const std::string& path, CameraConfig& cam) {
  const MapView view = r.Map(node, path);
  CameraIdentityKeys(cam).ReadKeys(r, view);
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

// enclosure.floor: a list of [x, y] points in metres, at most GroundPolygon::kMaxVertices.
bool ReadFloor(Reader& r, const MapView& view, const std::string& key, GroundPolygon& out) {
  const YAML::Node* floor = ListValue(r, view, key, "a list of [x, y] points in metres");
  if (!floor) return false;
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
      r.msg().Error(path,
                    "expected a point [x, y] in metres, got " +
                        (p.IsSequence() ? "a list of " + std::to_string(p.size()) : ShapeOf(p)));
      continue;
    }
    vertices.emplace_back(x, y);
  }
  out = GroundPolygon(std::move(vertices));
  return true;
}

// wall_height_m tunes the pipeline's usability tests: bound to their field.
OptionsBinder EnclosureKeys(StationConfig& cfg) {
  EnclosureConfig& e = cfg.enclosure;
  OptionsBinder b;
  b.AddRead(
       "floor", "none",
       "the floor polygon in ground metres (z = 0, the frame of the camera models), corners in "
       "order around it (either direction). At least 3 points and at most 100,000 (what the "
       "YAML reader holds in memory while it parses: ~1.5 KB a point), not crossing itself "
       "(checked in O(n log n)), no repeated point, non-zero area. A sprite is usable only if "
       "its contact point lies inside it (minus `pipeline.wall_margin_m`). `ingest` needs it "
       "(it can take it from a synthetic session's truth, as a replayed camera of the daemon "
       "does). The daemon starts without it, so that the console's calibration wizard can find "
       "it (its enclosure step): every camera then streams for preview and recording and "
       "stores no sprites, its tile on the station page says `no floor: calibrate`, and "
       "`config check` lists it under `to calibrate`",
       [&e](Reader& r, const MapView& view, const std::string& key) {
         return ReadFloor(r, view, key, e.floor);
       })
      .Type("list of `[x, y]`")
      .Default("none")
      .Add("wall_height_m", &cfg.pipeline.usability.wall_height_m, "a number >= 0",
           "walls along the polygon's edges hide the floor behind them up to this height "
           "(metres); used to decide what the camera sees as floor")
      .Rule(AtLeast(0));
  return b;
}

// Each key bound straight to the stage option it sets (pipeline/run/camera_pipeline.h).
OptionsBinder PipelineKeys(CameraPipelineOptions& p) {
  OptionsBinder b;
  b.Add("min_area_px", &p.extract.min_area, "at least 1 pixel",
        "matte blobs smaller than this (pixels) are noise")
      .Rule(AtLeast(1))
      .Add("border_margin_px", &p.usability.border_margin_px, "a number of pixels >= 0",
           "a sprite this close to the image border is not usable")
      .Rule(AtLeast(0))
      .Add("floor_margin_px", &p.usability.floor_margin_px, "a number of pixels >= 0",
           "floor pixels required all around the silhouette (else it touches a wall)")
      .Rule(AtLeast(0))
      .Add("wall_margin_m", &p.usability.wall_margin_m, "a distance in metres >= 0",
           "the contact point must lie this far inside the floor polygon")
      .Rule(AtLeast(0))
      .Add("max_view_angle_deg", &p.usability.max_view_angle_deg,
           "an angle in degrees above 0 and at most 90 (90: no view is too steep)",
           "sprites seen more steeply than this (the angle at the contact point between the "
           "floor and the ray to the camera) are refused as `view_too_steep`: an upright "
           "billboard from above is a sliver (docs/pipeline.md). 90 keeps every view")
      .Rule({0, 90, true})
      .Add("floor_view_angle_deg", &p.usability.floor_view_angle_deg,
           "an angle in degrees above 0 and at most 90 (90: no camera films from above)",
           "a camera whose median view of its floor is steeper than this films from above: its "
           "subjects are laid on the floor as floor sprites, which `max_view_angle_deg` does "
           "not limit (docs/pipeline.md)")
      .Rule({0, 90, true})
      .Add("floor_height_m", &p.rectify.floor_height_m, "a distance in metres >= 0",
           "floor sprites: the height above the floor of the plane a subject seen from above is "
           "laid on, where its outline lies (the widest part of its body)")
      .Rule(AtLeast(0))
      .Add("still_speed_m_per_s", &p.still_speed_m_per_s, "a positive speed in m/s",
           "a subject slower than this is standing still")
      .Rule(Positive())
      .Add("max_speed_m_per_s", &p.track.max_speed_m_per_s, "a positive speed in m/s",
           "the tracker's speed limit: a candidate farther from a subject than this speed (plus "
           "2 cm) allows is a new subject, its clip a new clip. 1 m/s suits small animals; "
           "people walk at ~1.4 m/s (use 2.5 for them: `import` writes it into its "
           "`ingest.yaml`)")
      .Rule(Positive())
      .Add("max_still_s", &p.max_still_s, "a positive duration in seconds",
           "still periods longer than this are discarded (seed 000: extended periods without "
           "motion)")
      .Rule(Positive())
      .Add("min_clip_frames", &p.batch.min_clip_frames, "at least 1 frame",
           "clips shorter than this are discarded")
      .Rule(AtLeast(1))
      .Add("noise_recover_solidity", &p.noise.recover_solidity,
           "a share from 0 to 1 (0 turns the test off)",
           "a subject discarded as `noise` in its previous frame stays `noise` until its "
           "solidity reaches this (keyed background flickers about the threshold); `0` = no "
           "memory")
      .Rule(Between(0, 1))
      .Add("noise_thick_px", &p.noise.thick_px, "a distance in pixels >= 0",
           "a matte pixel more than this many pixels from the matte's edge is interior (for "
           "`noise_min_thick_share`)")
      .Rule(AtLeast(0))
      .Add("noise_min_thick_share", &p.noise.min_thick_share,
           "a share from 0 to 1 (0 turns the test off)",
           "also `noise` when less of the matte is interior (specks, thin lines); `0` is off")
      .Rule(Between(0, 1))
      .Add("noise_min_solidity", &p.noise.min_solidity,
           "a share from 0 to 1 (0 turns the test off)",
           "a sprite whose matte (alpha > 1/2, in the camera image) fills less than this share "
           "of its convex hull is discarded as `noise`: keyed background, alone or joined to a "
           "subject (docs/pipeline.md); `0` turns it off")
      .Rule(Between(0, 1))
      .Add("noise_min_largest_share", &p.noise.min_largest_share,
           "a share from 0 to 1 (0 turns the test off)",
           "also `noise` when the matte's largest 8-connected part holds less of it "
           "(fragments); `0` is off")
      .Rule(Between(0, 1))
      .Add("noise_min_mean_alpha", &p.noise.min_mean_alpha,
           "a share from 0 to 1 (0 turns the test off)",
           "also `noise` when the mean alpha over the matte's pixels of alpha >= 16/255 is lower "
           "(a soft haze); `0` is off")
      .Rule(Between(0, 1))
      .Add("merged_min_width_ratio", &p.side_by_side.min_width_ratio, "0 or a ratio of at least 1",
           "two subjects side by side in one blob, which the tracks never saw apart (they "
           "walked in together), are tagged `merged` when the billboard's matte splits into a "
           "left and a right part and is this many times as wide as one subject of the camera "
           "(the median of the sprites counted one); the clip's later and earlier sprites that "
           "are as wide are tagged too (docs/pipeline.md \"Merged subjects\"); `0` turns the "
           "rule off")
      .Type("`0` or number >= 1")
      .AddRead("px_per_m", "auto",
               "billboard scale in pixels per metre, one for the whole bank. `auto`: a bank that "
               "holds sprites keeps its own scale; for an empty bank it is chosen from the "
               "cameras (the finest camera's floor resolution at the floor's centre, capped so "
               "that anything a camera sees whole standing on the floor fits 512 px; "
               "docs/pipeline.md, \"The bank's scale\"). A number sets it for an empty bank; a "
               "number other than the scale a bank already holds is an error naming both",
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
      .Type("`auto` or number > 0")
      .Add("workers", &p.workers, "0 (one per core) or more threads",
           "threads OpenCV may spread one frame's image operations over (colour conversion, "
           "resampling); the pipeline itself runs one thread per camera, so with several "
           "cameras `1` avoids oversubscribing the cores; `0` = OpenCV's default (one per core)")
      .Rule(AtLeast(0))
      .Add("queue_frames", &p.queue_frames, "at least 1 frame",
           "per-camera queue between the capture thread and the pipeline; a full queue drops "
           "(and counts) frames")
      .Rule(AtLeast(1))
      .Type("integer 1..1024");
  return b;
}

OptionsBinder TransitionsKeys(TransitionsConfig& t) {
  OptionsBinder b;
  b.Add("include_merged", &t.include_merged,
        "sprites tagged `merged` (two or more subjects in one blob, docs/pipeline.md \"Merged "
        "subjects\") take part in the transitions the station (and `ingest --config`) keeps "
        "current. Off: they are stored but no transition leaves or reaches them, and a table "
        "made with them loses their transitions at the next start. `spritestation transitions "
        "BANK` and `transitions worker` take `--include-merged` instead; every worker of a "
        "PostgreSQL bank must agree (docs/transitions.md)");
  b.Add("max_per_sprite", &t.max_per_sprite, "0 or more",
        "at most this many transitions leave a sprite: its cheapest (by cost, then by the id of "
        "the sprite it reaches). 0 keeps every one. From above a walking animal's frames look "
        "alike once turned to one heading, and without a cap the table grows with the square of "
        "the session. `spritestation transitions BANK` and `transitions worker` take "
        "`--max-per-sprite` instead; every worker of a PostgreSQL bank must agree "
        "(docs/transitions.md \"At most K out of a sprite\")")
      .Rule(AtLeast(0));
  return b;
}

std::vector<std::string> RecordingCodecNames() {
  std::vector<std::string> names;
  for (const RecordingCodec& c : RecordingCodecs()) names.push_back(c.name);
  return names;
}

OptionsBinder StorageKeys(StorageConfig& s) {
  OptionsBinder b;
  b.AddRead("bank", s.bank,
            "the sprite bank: one SQLite file, created if missing, or a PostgreSQL database "
            "shared by many stations, its schema created by the first writer (docs/scaling.md). "
            "A folder or a device (`/dev/null`) is refused, by `config check` with the daemon's "
            "words: `FILE: not a sprite bank (a folder)`, `... (not a regular file)`",
            [&s](Reader& r, const MapView& view, const std::string& key) {
              // A file (resolved against the config's folder) or a PostgreSQL address, kept as
              // written.
              if (!r.Path(view, key, s.bank)) return false;
              std::string raw;
              r.String(view, key, raw, "a path");
              if (sql::IsPostgresAddress(raw)) s.bank = raw;
              return true;
            })
      .Type("path or `postgresql://…`")
      .AddPath("recording_dir", &s.recording_dir, "where recorded sessions are written")
      .AddEnum("recording", &s.recording, kRecordingModeTexts,
               "raw recording: none, every frame, or only frames that gave a usable sprite")
      .Add("recording_codec", &s.recording_codec, "a string",
           "codec of recorded video: ffv1 is lossless with a CRC per slice; ffvhuff is "
           "lossless, ~8x faster to decode at 1080p, ~14 % larger, without checksums "
           "(docs/formats.md)")
      .Type(OptionsBinder::Choices(RecordingCodecNames()))
      .Add("stop_recording_below_mib", &s.stop_recording_below_mib, "a size >= 0",
           "when free disk space falls below this (MiB), raw recording stops first")
      .Rule(AtLeast(0))
      .Add("stop_sprites_below_mib", &s.stop_sprites_below_mib, "a size >= 0",
           "below this, sprite storage stops too (the bank is committed, never corrupted); "
           "`stop_recording_below_mib` is raised to at least this (adjusted)")
      .Rule(AtLeast(0))
      .AddPath("spool_dir", &s.spool_dir,
               "where clip batches wait on disk while the bank cannot take them (a PostgreSQL "
               "server gone, a SQLite file locked past every retry); drained in order when it "
               "answers, also at the next start (docs/daemon.md)")
      .Add("spool_max_mib", &s.spool_max_mib, "a size >= 1",
           "the most the spool may hold (MiB); a batch beyond it fails as an append would "
           "(counted, logged)")
      .Rule(AtLeast(1));
  return b;
}

OptionsBinder ControlKeys(ControlConfig& c) {
  OptionsBinder b;
  b.Add("address", &c.address, "an IP address",
        "address the HTTP control API binds to; `0.0.0.0` or `::` for every interface")
      .Type("IP address or `localhost`")
      .Add("port", &c.port, "a port number 0..65535",
           "its port; `0` picks a free port (the daemon logs and reports it)")
      .Rule(Between(0, 65535))
      .Add("token", &c.token, "a string",
           "bearer token clients must send. **Required when `address` is not loopback** "
           "(127.0.0.0/8, `::1`, `localhost`); at least 16 characters")
      .AddRead(
          "token_file", "none",
          "read the token from this file's first line instead (keeps secrets out of the "
          "config); give `token` or `token_file`, not both",
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
          })
      .Type("path")
      .Default("none");
  return b;
}

OptionsBinder LoggingKeys(LoggingConfig& l) {
  OptionsBinder b;
  b.Add("level", &l.level, "a log level", "level of every component")
      .Type(OptionsBinder::Choices(kLogLevels))
      .AddRead("components", "{}",
               "per-component levels, e.g. `capture.aravis: debug`, `pipeline.key: warn`",
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
               })
      .Type("mapping component → level");
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
  if (!cfg.pipeline.keying) cfg.pipeline.keying.emplace();  // the keying section's home
  OptionsBinder b;
  b.Add("version", &cfg.version, "a config version number",
        "config format version; a newer version is refused with a clear message")
      .AddRead("cameras", "[]",
               "the cameras; given, at least one (`cameras: []` is refused). Without the key "
               "the daemon refuses the file and `config check` says so under `the daemon "
               "refuses it:`, with exit 0: `ingest --config` takes the session's cameras",
               [&cfg](Reader& r, const MapView& view, const std::string& key) {
                 const YAML::Node* cams = ListValue(r, view, key, "a list of cameras");
                 if (!cams) return false;
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
      .Type("list of [camera](#cameras)");
  // The blocks, each a table of its own.
  const auto section = [&b](const char* key, const char* doc, OptionsBinder::ReadFn read) {
    b.AddRead(key, "", doc, std::move(read))
        .Type("[mapping](#" + std::string(key) + ")")
        .Default("see below");
  };
  section("keying", "how frames become mattes", Section(KeyingKeys, *cfg.pipeline.keying));
  section("enclosure", "the floor the subjects walk on", Section(EnclosureKeys, cfg));
  section("pipeline", "thresholds of the live pipeline", Section(PipelineKeys, cfg.pipeline));
  section("transitions", "which sprites take part in transitions",
          Section(TransitionsKeys, cfg.transitions));
  section("storage", "bank, recordings, disk limits", Section(StorageKeys, cfg.storage));
  section("control", "the HTTP control API", Section(ControlKeys, cfg.control));
  section("logging", "log levels", Section(LoggingKeys, cfg.logging));
  return b;
}

StationConfig Defaults() {
  StationConfig cfg;
  cfg.pipeline.keying.emplace();
  cfg.storage.bank = "station.bank";
  cfg.storage.recording_dir = "recordings";
  cfg.storage.spool_dir = "spool";
  return cfg;
}

namespace {

// Where a camera key's row says it applies: every backend, every live one (those that take
// the device settings), or the backends by name.
std::string SourcesCell(const std::vector<std::string>& backends) {
  std::vector<std::string> all, live;
  for (const CameraBackend* backend : CameraBackends()) {
    all.push_back(backend->name);
    if (backend->device_settings) live.push_back(backend->name);
  }
  if (backends == all) return "all";
  if (backends == live) return "live";
  return Join(backends, ", ");
}

// One Markdown table: its header, then a row of cells each; '|' in a cell is escaped.
std::string Table(const std::vector<std::string>& header,
                  const std::vector<std::vector<std::string>>& rows) {
  const auto line = [](const std::vector<std::string>& cells) {
    std::string out = "|";
    for (std::string cell : cells) {
      for (size_t at = cell.find('|'); at != std::string::npos; at = cell.find('|', at + 2))
        cell.replace(at, 1, "\\|");
      out += " " + cell + " |";
    }
    return out + "\n";
  };
  std::string out = line(header) + "|";
  for (size_t i = 0; i < header.size(); ++i) out += "---|";
  out += "\n";
  for (const auto& row : rows) out += line(row);
  return out;
}

// The cameras' keys: name and source, then every backend's in the order the backends bind
// them, each with the backends that take it ("all", "live" or names); a key two backends
// document apart gets both docs. Each row: key, type, default, sources, doc.
std::vector<std::vector<std::string>> CameraRows() {
  struct Entry {
    OptionsBinder::Row row;
    std::vector<std::pair<std::string, std::string>> docs;  // backend, its doc of the key
  };
  std::vector<Entry> entries;
  CameraConfig scratch;
  for (const OptionsBinder::Row& r : CameraIdentityKeys(scratch).Rows()) entries.push_back({r, {}});
  for (const CameraBackend* backend : CameraBackends()) {
    CameraConfig cam;
    cam.source = backend->name;
    for (const OptionsBinder::Row& r : CameraSettingKeys(cam).Rows()) {
      auto it = std::find_if(entries.begin(), entries.end(),
                             [&](const Entry& e) { return e.row.key == r.key; });
      if (it == entries.end()) it = entries.insert(entries.end(), Entry{r, {}});
      it->docs.emplace_back(backend->name, r.doc);
    }
  }
  std::vector<std::vector<std::string>> rows;
  for (const Entry& e : entries) {
    std::vector<std::string> backends, docs;
    bool one_doc = true;
    for (const auto& [backend, doc] : e.docs) {
      backends.push_back(backend);
      docs.push_back(backend + ": " + doc);
      one_doc = one_doc && doc == e.row.doc;
    }
    rows.push_back({e.row.key, e.row.type, e.row.default_cell,
                    backends.empty() ? "all" : SourcesCell(backends),
                    one_doc ? e.row.doc : Join(docs, "; ")});
  }
  return rows;
}

constexpr const char* kTableBegin = "<!-- generated by `spritestation config keys --markdown`: ";
constexpr const char* kTableEnd = "<!-- end of generated table -->";

// One table of docs/config.md: its keys' rows (key, type, default, [sources,] doc) and the
// path its keys stand under in a config ("keying.", "cameras[].").
struct KeyBlock {
  std::string name, prefix;
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
};

KeyBlock Block(std::string name, std::string prefix, const OptionsBinder& keys) {
  KeyBlock block{std::move(name), std::move(prefix), {"key", "type", "default", "meaning"}, {}};
  for (const OptionsBinder::Row& r : keys.Rows())
    block.rows.push_back({r.key, r.type, r.default_cell, r.doc});
  return block;
}

// Every table, in the order of docs/config.md, of a config of the defaults.
std::vector<KeyBlock> KeyBlocks() {
  StationConfig cfg = Defaults();
  CameraConfig cam;
  return {Block("top", "", StationKeys(cfg)),
          {"cameras", "cameras[].", {"key", "type", "default", "sources", "meaning"}, CameraRows()},
          Block("white_balance", "cameras[].white_balance.", WhiteBalanceKeys(cam.white_balance)),
          Block("keying", "keying.", KeyingKeys(*cfg.pipeline.keying)),
          Block("enclosure", "enclosure.", EnclosureKeys(cfg)),
          Block("pipeline", "pipeline.", PipelineKeys(cfg.pipeline)),
          Block("transitions", "transitions.", TransitionsKeys(cfg.transitions)),
          Block("storage", "storage.", StorageKeys(cfg.storage)),
          Block("control", "control.", ControlKeys(cfg.control)),
          Block("logging", "logging.", LoggingKeys(cfg.logging))};
}

// A block's table in Markdown, its keys as code.
std::string TableOf(const KeyBlock& block) {
  std::vector<std::vector<std::string>> rows = block.rows;
  for (auto& row : rows) row[0] = "`" + row[0] + "`";
  return Table(block.header, rows);
}

}  // namespace

}  // namespace ss::config_detail

namespace ss {

std::string ConfigKeysMarkdown() {
  std::string out;
  for (const config_detail::KeyBlock& block : config_detail::KeyBlocks())
    out += (out.empty() ? "" : "\n") + std::string(config_detail::kTableBegin) + block.name +
           " -->\n" + TableOf(block) + config_detail::kTableEnd + "\n";
  return out;
}

std::string WithConfigKeyTables(const std::string& doc, const std::string& origin) {
  const std::vector<config_detail::KeyBlock> blocks = config_detail::KeyBlocks();
  std::vector<std::string> seen;
  std::string out;
  size_t at = 0;
  for (size_t begin; (begin = doc.find(config_detail::kTableBegin, at)) != std::string::npos;) {
    const size_t name_at = begin + std::strlen(config_detail::kTableBegin);
    const size_t name_end = doc.find(" -->", name_at);
    const size_t end = doc.find(config_detail::kTableEnd, name_at);
    if (name_end == std::string::npos || end == std::string::npos || name_end > end)
      throw InputError(origin + ": a generated table's marker is not closed");
    const std::string name = doc.substr(name_at, name_end - name_at);
    const auto it = std::find_if(blocks.begin(), blocks.end(),
                                 [&](const config_detail::KeyBlock& b) { return b.name == name; });
    if (it == blocks.end()) throw InputError(origin + ": no key table named \"" + name + "\"");
    seen.push_back(name);
    out += doc.substr(at, name_end + 5 - at) + TableOf(*it);  // through " -->\n"
    at = end;
  }
  out += doc.substr(at);
  for (const config_detail::KeyBlock& block : blocks) {
    if (std::find(seen.begin(), seen.end(), block.name) == seen.end())
      throw InputError(origin + ": holds no key table \"" + block.name + "\" (" +
                       config_detail::kTableBegin + block.name + " -->)");
  }
  return out;
}

std::string ConfigKeysText() {
  std::string out;
  for (const config_detail::KeyBlock& block : config_detail::KeyBlocks()) {
    const bool sources = block.header.size() == 5;
    for (const auto& row : block.rows) {
      if (row[2] == "see below") continue;  // a block: its keys follow
      out += block.prefix + row[0] + " (" + row[1] + ", default " + row[2] +
             (sources ? ", sources " + row[3] : "") + "): " + row.back() + "\n";
    }
  }
  return out;
}

}  // namespace ss
