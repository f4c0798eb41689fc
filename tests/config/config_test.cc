// The station config: a complete file parses into every field, defaults are
// filled, and each kind of mistake is refused naming the field and its line.
#include "config/station_config.h"

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <stdexcept>

#include <gtest/gtest.h>

#include <cmath>

#include "capture/aravis/aravis_source.h"
#include "capture/camera_backend.h"
#include "capture/replay/replay_source.h"
#include "capture/v4l2/v4l2_source.h"
#include "core/bank_schema.h"
#include "core/error.h"
#include "core/option_checks.h"
#include "core/options_binder.h"
#include "core/sql.h"
#include "pipeline/key/chroma_keyer.h"
#include "pipeline/key/clean_plate_keyer.h"
#include "tests/support/test_support.h"

namespace ss {
namespace {

using ss::testing::ScratchDir;
namespace fs = std::filesystem;

const std::string kExample = fs::path(ss::testing::SourcePath("docs/station.example.yaml"));

ConfigOptions NoFileChecks() {
  ConfigOptions o;
  o.check_files = false;
  return o;
}

StationConfig Parse(const std::string& yaml, ConfigReport* report = nullptr) {
  return ParseStationConfig(yaml, "station.yaml", "/studio", report, NoFileChecks());
}

// The InputError message for `yaml`; fails the test when it parses.
std::string ErrorOf(const std::string& yaml, const ConfigOptions& options = NoFileChecks()) {
  try {
    ParseStationConfig(yaml, "station.yaml", "/studio", nullptr, options);
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected InputError for:\n" << yaml;
  return {};
}

const std::string kOneCamera =
    "cameras:\n  - name: cam0\n    source: v4l2\n    device: /dev/video0\n";

// Issue 20: a floor of 100,000 points took 43 s to check (every pair of edges). The check is a
// sweep now, and the limit is what the reader holds in memory while it parses: a floor of
// kMaxVertices points is read and checked; one more is refused by its size, before any check,
// naming the field and the limit.
TEST(StationConfig, AFloorPolygonHasABoundedSize) {
  const auto floor = [](size_t points) {
    std::string text = "[";
    for (size_t i = 0; i < points; ++i) {
      const double a = 2 * M_PI * static_cast<double>(i) / static_cast<double>(points);
      text += (i ? ", [" : "[") + std::to_string(10 * std::cos(a)) + ", " +
              std::to_string(10 * std::sin(a)) + "]";
    }
    return text + "]";
  };
  constexpr size_t kMax = GroundPolygon::kMaxVertices;
  const StationConfig cfg = Parse(kOneCamera + "enclosure:\n  floor: " + floor(kMax) + "\n");
  EXPECT_EQ(cfg.enclosure.floor.vertices().size(), kMax);
  const std::string error = ErrorOf(kOneCamera + "enclosure:\n  floor: " + floor(kMax + 1) + "\n");
  EXPECT_NE(error.find("enclosure.floor: " + std::to_string(kMax + 1) +
                       " points; a floor polygon has at most " + std::to_string(kMax)),
            std::string::npos)
      << error.substr(0, 300);
}

TEST(StationConfig, ExampleParsesIntoEveryField) {
  ConfigReport report;
  const StationConfig cfg = LoadStationConfig(kExample, &report, NoFileChecks());
  EXPECT_EQ(report.status, ConfigStatus::kValid) << report.Summary();
  const std::string dir = fs::path(kExample).parent_path().string();
  ASSERT_EQ(cfg.cameras.size(), 3u);

  const CameraConfig& replay = cfg.cameras[0];
  EXPECT_EQ(replay.name, "cam0");
  EXPECT_EQ(replay.source, "replay");
  EXPECT_EQ(replay.backend.Get<ReplayCameraKeys>(),
            (ReplayCameraKeys{dir + "/recordings/sample", "cam0", true, true}));
  EXPECT_EQ(replay.model, "");

  const CameraConfig& v4l2 = cfg.cameras[1];
  EXPECT_EQ(v4l2.source, "v4l2");
  EXPECT_EQ(v4l2.backend.Get<V4l2CameraKeys>().device, "/dev/video0");
  EXPECT_EQ(v4l2.pixel_format, "yuyv");
  EXPECT_EQ(v4l2.width, 1280);
  EXPECT_EQ(v4l2.height, 720);
  EXPECT_EQ(v4l2.fps, 30);
  EXPECT_EQ(v4l2.exposure_us, 8000);
  EXPECT_EQ(v4l2.gain_db, 0);
  EXPECT_EQ(v4l2.white_balance.mode, WhiteBalanceMode::kOnce);
  EXPECT_EQ(v4l2.model, dir + "/models/side.cameramodel");

  const CameraConfig& gige = cfg.cameras[2];
  EXPECT_EQ(gige.source, "aravis");
  EXPECT_EQ(gige.backend.Get<AravisCameraKeys>(),
            (AravisCameraKeys{"", "192.168.10.21", true, 8192}));
  EXPECT_EQ(gige.pixel_format, "bayer_rg8");
  EXPECT_EQ(gige.fps, 60);
  EXPECT_EQ(gige.exposure_us, 4000);
  EXPECT_EQ(gige.gain_db, 2.5);
  EXPECT_EQ(gige.white_balance.mode, WhiteBalanceMode::kManual);
  EXPECT_EQ(gige.white_balance.red_gain, 1.42);
  EXPECT_EQ(gige.white_balance.blue_gain, 1.87);

  EXPECT_EQ(cfg.pipeline.keying->method, "chroma");
  EXPECT_EQ(cfg.pipeline.keying->training_frames, 30);
  EXPECT_EQ(cfg.pipeline.keying->Block<ChromaKeyBlock>("chroma"), (ChromaKeyBlock{20, 60}));
  EXPECT_EQ(cfg.pipeline.keying->Block<CleanPlateKeyBlock>("clean_plate"),
            (CleanPlateKeyBlock{3, 6}));
  EXPECT_TRUE(cfg.pipeline.keying->despill.enabled);
  EXPECT_EQ(cfg.pipeline.keying->despill.strength, 1.0);
  EXPECT_TRUE(cfg.pipeline.keying->shadow.enabled);
  EXPECT_EQ(cfg.pipeline.keying->shadow.min_darkening, 0.08);
  EXPECT_EQ(cfg.pipeline.keying->shadow.max_darkening, 0.7);
  EXPECT_EQ(cfg.pipeline.keying->shadow_reach_m, 0.5);

  ASSERT_EQ(cfg.enclosure.floor.vertices().size(), 4u);
  EXPECT_EQ(cfg.enclosure.floor.vertices()[2], Eigen::Vector2d(1.2, 0.8));
  EXPECT_NEAR(cfg.enclosure.floor.Area(), 2.4 * 1.6, 1e-12);
  EXPECT_EQ(cfg.pipeline.usability.wall_height_m, 0.6);

  EXPECT_EQ(cfg.pipeline.extract.min_area, 400);
  EXPECT_EQ(cfg.pipeline.usability.border_margin_px, 2);
  EXPECT_EQ(cfg.pipeline.usability.floor_margin_px, 3);
  EXPECT_EQ(cfg.pipeline.usability.wall_margin_m, 0.005);
  EXPECT_EQ(cfg.pipeline.still_speed_m_per_s, 0.05);
  EXPECT_EQ(cfg.pipeline.track.max_speed_m_per_s, 1.5);
  EXPECT_EQ(cfg.pipeline.max_still_s, 2.0);
  EXPECT_EQ(cfg.pipeline.batch.min_clip_frames, 5);
  EXPECT_EQ(cfg.pipeline.rectify.px_per_m, 0);  // auto
  EXPECT_EQ(cfg.pipeline.workers, 0);
  EXPECT_EQ(cfg.pipeline.queue_frames, 8);
  EXPECT_EQ(cfg.pipeline.noise.min_solidity, 0.25);
  EXPECT_EQ(cfg.pipeline.noise.recover_solidity, 0.30);
  EXPECT_EQ(cfg.pipeline.noise.min_thick_share, 0);  // off

  EXPECT_EQ(cfg.storage.bank, dir + "/station.bank");
  EXPECT_EQ(cfg.storage.recording_dir, dir + "/recordings");
  EXPECT_EQ(cfg.storage.recording, RecordingMode::kUsable);
  EXPECT_EQ(cfg.storage.recording_codec, "ffv1");
  EXPECT_EQ(cfg.storage.stop_recording_below_mib, 20480);
  EXPECT_EQ(cfg.storage.stop_sprites_below_mib, 2048);

  EXPECT_EQ(cfg.control.address, "127.0.0.1");
  EXPECT_EQ(cfg.control.port, 8360);
  EXPECT_EQ(cfg.control.token, "");
  EXPECT_EQ(cfg.logging.level, "info");
  EXPECT_EQ(cfg.logging.components.at("capture.aravis"), "debug");
}

TEST(StationConfig, DefaultsAreFilled) {
  ConfigReport report;
  const StationConfig cfg = Parse(kOneCamera, &report);
  EXPECT_EQ(report.status, ConfigStatus::kValid);
  StationConfig expected;
  CameraConfig cam;
  cam.name = "cam0";
  cam.source = "v4l2";
  cam.backend.Use<V4l2CameraKeys>().device = "/dev/video0";
  expected.cameras = {cam};
  expected.storage.bank = "/studio/station.bank";
  expected.storage.recording_dir = "/studio/recordings";
  expected.storage.spool_dir = "/studio/spool";
  EXPECT_EQ(cfg, expected);
  EXPECT_FALSE(cfg.cameras[0].exposure_us.has_value());  // unset: the device's value, locked
  EXPECT_EQ(cfg.control.address, "127.0.0.1");
  EXPECT_EQ(cfg.pipeline.keying->method, "chroma");
  EXPECT_TRUE(cfg.enclosure.floor.empty());
}

TEST(StationConfig, PxPerMIsAutoOrANumber) {
  EXPECT_EQ(Parse(kOneCamera + "pipeline:\n  px_per_m: auto\n").pipeline.rectify.px_per_m, 0);
  EXPECT_EQ(Parse(kOneCamera + "pipeline:\n  px_per_m: 500\n").pipeline.rectify.px_per_m, 500);
}

TEST(StationConfig, ReplayCameraDefaultsToItsOwnNameInTheSession) {
  const StationConfig cfg =
      Parse("cameras:\n  - {name: left, source: replay, session: /data/s1}\n");
  EXPECT_EQ(cfg.cameras[0].backend.Get<ReplayCameraKeys>(),
            (ReplayCameraKeys{"/data/s1", "left", false, true}));
}

TEST(StationConfig, WrongTypeNamesFieldAndLine) {
  const std::string yaml = kOneCamera +
                           "  - name: cam1\n"    // line 5
                           "    source: v4l2\n"  // line 6
                           "    device: /dev/video1\n"
                           "    fps: fast\n";  // line 8
  EXPECT_EQ(ErrorOf(yaml),
            "station.yaml:8: cameras[1].fps: expected a positive number, got \"fast\"");
  EXPECT_EQ(ErrorOf("pipeline:\n  min_area_px: 12.5\n"),
            "station.yaml:2: pipeline.min_area_px: expected at least 1 pixel, got \"12.5\"");
  EXPECT_EQ(ErrorOf("keying:\n  despill:\n    enabled: maybe\n"),
            "station.yaml:3: keying.despill.enabled: expected true or false, got \"maybe\"");
  EXPECT_EQ(ErrorOf("cameras: cam0\n"),
            "station.yaml:1: cameras: expected a list of cameras, got \"cam0\"");
  EXPECT_EQ(ErrorOf("storage:\n  bank: [a, b]\n"),
            "station.yaml:2: storage.bank: expected a path, got a list");
  EXPECT_EQ(ErrorOf("pipeline: 3\n"),
            "station.yaml:1: pipeline: expected a mapping of keys, got \"3\"");
}

TEST(StationConfig, UnknownKeysAreRefusedByName) {
  const std::string yaml =
      "cameras:\n  - name: cam0\n    source: v4l2\n    device: /dev/video0\n    fsp: 30\n";
  EXPECT_EQ(ErrorOf(yaml), "station.yaml:5: cameras[0].fsp: unknown key (did you mean \"fps\"?)");
  EXPECT_EQ(ErrorOf("pipline:\n  px_per_m: 500\n"),
            "station.yaml:1: pipline: unknown key (did you mean \"pipeline\"?)");
  EXPECT_EQ(ErrorOf("control:\n  colour: blue\n"), "station.yaml:2: control.colour: unknown key");
  // A key of another source is named as such.
  EXPECT_EQ(
      ErrorOf("cameras:\n  - name: c\n    source: aravis\n    address: 10.0.0.2\n    device: "
              "/dev/video0\n"),
      "station.yaml:5: cameras[0].device: only for source v4l2 (this camera's source is aravis)");
  EXPECT_EQ(ErrorOf("cameras:\n  - name: c\n    source: replay\n    session: s\n    fps: 30\n"),
            "station.yaml:5: cameras[0].fps: only for source aravis or libcamera or v4l2 (this "
            "camera's source is replay)");
}

TEST(StationConfig, ValueErrorsNameFieldAndLine) {
  struct Case {
    std::string yaml, error;
  };
  const std::vector<Case> cases = {
      {"cameras:\n  - name: c\n    source: usb\n",
       "station.yaml:3: cameras[0].source: expected one of aravis, libcamera, replay, v4l2, got "
       "\"usb\""},
      {"cameras:\n  - name: c\n    source: v4l2\n",
       "station.yaml:2: cameras[0].device: a v4l2 camera needs its device, e.g. /dev/video0"},
      {"cameras:\n  - source: v4l2\n    device: /dev/video0\n",
       "station.yaml:2: cameras[0].name: every camera needs a name"},
      {"cameras:\n  - name: c\n    source: aravis\n",
       "station.yaml:2: cameras[0].camera_id: an aravis camera needs "
       "camera_id or address"},
      {"cameras:\n  - name: c\n    source: aravis\n    address: 10.0.0.300\n",
       "station.yaml:4: cameras[0].address: expected an IP address, got \"10.0.0.300\""},
      {kOneCamera + "    pixel_format: rgb24\n",
       "station.yaml:5: cameras[0].pixel_format: expected one of mono8, bayer_rg8, bayer_gr8, "
       "bayer_gb8, bayer_bg8, "
       "rgb8, bgr8, yuyv, nv12, mjpeg, got \"rgb24\""},
      {kOneCamera + "    fps: -30\n",
       "station.yaml:5: cameras[0].fps: expected a positive number, got -30"},
      {kOneCamera + "    width: 640\n",
       "station.yaml:2: cameras[0].height: give width and height together"},
      {kOneCamera + "    exposure_us: 0\n",
       "station.yaml:5: cameras[0].exposure_us: expected a positive number, got 0"},
      {kOneCamera + "    white_balance: {mode: once, red_gain: 1.2}\n",
       "station.yaml:5: cameras[0].white_balance.red_gain: only applies with mode: manual"},
      {kOneCamera + "    white_balance: {mode: manual, red_gain: 1.2, temperature_k: 5600}\n",
       "station.yaml:5: cameras[0].white_balance.temperature_k: give either the red/blue gains or "
       "a colour "
       "temperature, not both"},
      {kOneCamera + "    white_balance: {mode: manual, red_gain: 1.2}\n",
       "station.yaml:5: cameras[0].white_balance.temperature_k: V4L2 devices fix white balance as "
       "a colour "
       "temperature: give temperature_k"},
      {kOneCamera + "    white_balance: {mode: manual, temperature_k: 560}\n",
       "station.yaml:5: cameras[0].white_balance.temperature_k: expected a colour temperature of "
       "1500-15000 K, "
       "got 560"},
      {kOneCamera + kOneCamera.substr(9),
       "station.yaml:5: cameras[1].name: \"cam0\" is already the name of cameras[0]"},
      {"keying:\n  chroma: {low: 80, high: 40}\n",
       "station.yaml:2: keying.chroma.high: must be above low (80), got 40"},
      {"keying:\n  method: luma\n",
       "station.yaml:2: keying.method: expected one of chroma, clean_plate, got \"luma\""},
      {"pipeline:\n  px_per_m: 0\n",
       "station.yaml:2: pipeline.px_per_m: expected auto or a positive number, got 0"},
      {"pipeline:\n  px_per_m: big\n",
       "station.yaml:2: pipeline.px_per_m: expected auto or a positive number of pixels per metre, "
       "got \"big\""},
      {"pipeline:\n  min_area_px: 0\n",
       "station.yaml:2: pipeline.min_area_px: expected at least 1 pixel, got 0"},
      {"storage:\n  recording: some\n",
       "station.yaml:2: storage.recording: expected one of off, all, usable, got \"some\""},
      {"control:\n  port: 70000\n",
       "station.yaml:2: control.port: expected a port number 0..65535, got 70000"},
      {"logging:\n  level: verbose\n",
       "station.yaml:2: logging.level: expected one of trace, debug, info, warn, error, critical, "
       "off, got \"verbose\""},
      {"version: 2\n",
       "station.yaml:1: version: written for a newer SpriteStation (config version 2); this one "
       "reads "
       "version 1"},
      {"enclosure:\n  floor: [[0, 0], [1, 1], [1, 0], [0, 1]]\n",
       "station.yaml:2: enclosure.floor: the polygon crosses itself, repeats a point, has a "
       "non-finite point or has "
       "no area (list the corners in order around the floor)"},
      {"enclosure:\n  floor:\n    - [0, 0]\n    - [1, 0, 2]\n    - [1, 1]\n",
       "station.yaml:4: enclosure.floor[1]: expected a point [x, y] in metres, got a list of 3"},
      {"enclosure:\n  floor: [[0, 0], [1, 0]]\n",
       "station.yaml:2: enclosure.floor: a floor polygon needs at least 3 points, got 2"},
      {kOneCamera + "    fps:\n",
       "station.yaml:5: cameras[0].fps: has no value (remove the key to use the default)"},
      {"pipeline:\n  px_per_m: 500\n  px_per_m: 600\n",
       "station.yaml:3: pipeline.px_per_m: given twice (lines 2 and 3)"},
  };
  for (const Case& c : cases) EXPECT_EQ(ErrorOf(c.yaml), c.error) << c.yaml;
}

TEST(StationConfig, EveryErrorIsReportedAtOnce) {
  const std::string yaml =
      "cameras:\n"
      "  - name: cam0\n"
      "    source: v4l2\n"
      "    device: /dev/video0\n"
      "    fps: fast\n"  // 5
      "pipeline:\n"
      "  px_per_m: -1\n"     // 7
      "  min_aera_px: 3\n";  // 8
  EXPECT_EQ(ErrorOf(yaml),
            "station.yaml:5: cameras[0].fps: expected a positive number, got \"fast\"\n"
            "station.yaml:8: pipeline.min_aera_px: unknown key (did you mean \"min_area_px\"?)\n"
            "station.yaml:7: pipeline.px_per_m: expected auto or a positive number, got -1");
}

// The keying and pipeline sections (and enclosure.wall_height_m) are the camera pipeline's own
// options (issue 17); the config's defaults are as they were where they differ from the
// stages' own (DefaultPipelineOptions).
TEST(StationConfig, PipelineSectionsAreTheStagesOptionsWithTheConfigsDefaults) {
  const CameraPipelineOptions p = Parse(kOneCamera).pipeline;
  ASSERT_TRUE(p.keying.has_value());
  EXPECT_EQ(*p.keying, KeyingConfig{});
  EXPECT_EQ(p.extract.min_area, 400);  // the extractor's own is 40
  EXPECT_EQ(p.usability.border_margin_px, 2);
  EXPECT_EQ(p.usability.floor_margin_px, 3);
  EXPECT_EQ(p.usability.wall_margin_m, 0.005);
  EXPECT_EQ(p.usability.wall_height_m, 0.0);
  EXPECT_EQ(p.still_speed_m_per_s, 0.05);
  EXPECT_EQ(p.track.max_speed_m_per_s, 1.0);
  EXPECT_EQ(p.max_still_s, 2.0);
  EXPECT_EQ(p.batch.min_clip_frames, 5);
  EXPECT_EQ(p.noise.thick_px, 2.0);
  EXPECT_EQ(p.noise.min_solidity, 0.25);
  EXPECT_EQ(p.noise.recover_solidity, 0.30);
  EXPECT_EQ(p.noise.min_thick_share, 0);
  EXPECT_EQ(p.noise.min_largest_share, 0);
  EXPECT_EQ(p.noise.min_mean_alpha, 0);
  EXPECT_EQ(p.rectify.px_per_m, 0);  // auto; the rectifier's own is 800
  EXPECT_EQ(p.workers, 0);
  EXPECT_EQ(p.queue_frames, 8);
  // What the config does not set is the stages' own.
  CameraPipelineOptions stages = p;
  stages.keying.reset();
  stages.extract.min_area = ExtractorOptions{}.min_area;
  stages.rectify.px_per_m = RectifierOptions{}.px_per_m;
  EXPECT_EQ(stages, CameraPipelineOptions{});

  const StationConfig set = Parse(
      "enclosure:\n  wall_height_m: 0.4\n"
      "pipeline:\n  min_area_px: 90\n  max_speed_m_per_s: 2\n  min_clip_frames: 7\n"
      "  px_per_m: 600\n");
  EXPECT_EQ(set.pipeline.usability.wall_height_m, 0.4);
  EXPECT_EQ(set.pipeline.extract.min_area, 90);
  EXPECT_EQ(set.pipeline.track.max_speed_m_per_s, 2);
  EXPECT_EQ(set.pipeline.batch.min_clip_frames, 7);
  EXPECT_EQ(set.pipeline.rectify.px_per_m, 600);
}

// keying.chroma.* and keying.clean_plate.* are the keyers' own blocks (ChromaKeyBlock,
// CleanPlateKeyBlock, held by KeyingConfig::keyers); the shared despill and shadow blocks are
// copied in whole when a keyer is made.
TEST(StationConfig, KeyerBlocksAreTheKeyersOptions) {
  const StationConfig cfg = Parse(
      "keying:\n  chroma: {low: 10, high: 50}\n  clean_plate: {low_sigma: 2, high_sigma: 9}\n"
      "  shadow: {max_darkening: 0.6}\n  despill: {strength: 0.25}\n");
  EXPECT_EQ(cfg.pipeline.keying->Block<ChromaKeyBlock>("chroma"), (ChromaKeyBlock{10, 50}));
  const ChromaKeyerOptions o = ChromaKeyerOptionsFrom(*cfg.pipeline.keying);
  EXPECT_EQ(o.key_low_levels, 10);
  EXPECT_EQ(o.key_high_levels, 50);
  EXPECT_EQ(o.shadow, (ShadowOptions{true, 0.08, 0.6}));
  EXPECT_EQ(o.despill, (DespillOptions{true, 0.25, 0.5}));
  EXPECT_EQ(o.noise_z, ChromaKeyerOptions{}.noise_z);  // not in the config: the keyer's own
  const CleanPlateKeyerOptions p = CleanPlateKeyerOptionsFrom(*cfg.pipeline.keying);
  EXPECT_EQ(p.low_sigma, 2);
  EXPECT_EQ(p.high_sigma, 9);
  EXPECT_EQ(p.shadow, o.shadow);
  EXPECT_EQ(p.ramp, CleanPlateKeyerOptions{}.ramp);
}

// A keyer made with values out of range says which field of which block, every one.
TEST(StationConfig, KeyerOptionsNameTheirBadFields) {
  ChromaKeyerOptions o;
  o.shadow.max_darkening = 0.01;  // below min_darkening
  o.despill.strength = 2;
  std::string why;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_EQ(why,
            "shadow.max_darkening: must be above min_darkening (0.06)\n"
            "despill.strength: expected a number 0..1, got 2");
  EXPECT_THROW(ChromaKeyer{o}, InputError);
  CleanPlateKeyerOptions p;
  p.high_sigma = 3;  // at or below low_sigma (4): neither 0 nor a ramp
  EXPECT_FALSE(p.IsValid(&why));
  EXPECT_EQ(why, "high_sigma: must be 0 (ramp by levels) or above low_sigma (4)");
  EXPECT_TRUE(CleanPlateKeyerOptions{}.IsValid(&why)) << why;
  EXPECT_TRUE(ChromaKeyerOptions{}.IsValid(&why)) << why;
}

// The config states no range of its own for the shared keyer blocks: ShadowOptions::IsValid is
// the rule (min_darkening within [0, 1), where the config once allowed 1), reported at its key.
TEST(StationConfig, ShadowValuesAreCheckedByTheKeyersRuleAtTheirKey) {
  EXPECT_EQ(ErrorOf("keying:\n  shadow: {min_darkening: 1, max_darkening: 1}\n"),
            "station.yaml:2: keying.shadow.min_darkening: expected a fraction >= 0, < 1, got 1\n"
            "station.yaml:2: keying.shadow.max_darkening: must be above min_darkening (1)");
  EXPECT_EQ(
      ErrorOf("keying:\n  shadow:\n    max_darkening: 0\n"),
      "station.yaml:3: keying.shadow.max_darkening: expected a fraction > 0, <= 1, got 0");  // first
                                                                                             // only
}

// The stages' own rules (their options' IsValid), each error naming the config key, all of them.
TEST(StationConfig, PipelineValuesAreCheckedByTheStagesNamingTheKey) {
  EXPECT_EQ(ErrorOf("enclosure:\n  wall_height_m: -0.5\n"
                    "pipeline:\n  min_clip_frames: 0\n  max_speed_m_per_s: -1\n"
                    "  noise_min_mean_alpha: 2\n  queue_frames: 0\n"),
            "station.yaml:2: enclosure.wall_height_m: expected a number >= 0, got -0.5\n"
            "station.yaml:5: pipeline.max_speed_m_per_s: expected a positive speed in m/s, got -1\n"
            "station.yaml:4: pipeline.min_clip_frames: expected at least 1 frame, got 0\n"
            "station.yaml:6: pipeline.noise_min_mean_alpha: expected a share from 0 to 1 (0 turns "
            "the test off), got 2\n"
            "station.yaml:7: pipeline.queue_frames: expected at least 1 frame, got 0");
}

// Every number of the pipeline block is bound with its bounds: a negative value (out of every
// one's) is refused at its own key, by the binding, not left for the stage to throw at a start.
// Every number of every section bound with a lower bound (its type says so: "integer >= 1",
// "number > 0", "0..1") is refused at its own key below it: a rule bound in a section whose
// checks never run (the validator forgot the section) fails here.
TEST(StationConfig, EveryBoundedNumberIsRefusedOutOfItsBounds) {
  std::istringstream lines(ConfigKeysText());
  std::map<std::string, int> checked;
  for (std::string line; std::getline(lines, line);) {
    const size_t paren = line.find(" (");
    if (paren == std::string::npos || line.rfind("cameras[]", 0) == 0) continue;
    const std::string key = line.substr(0, paren);
    const std::string type = line.substr(paren + 2, line.find(", default") - paren - 2);
    if (type.find("number") == std::string::npos && type.find("integer") == std::string::npos)
      continue;
    const bool bounded = type.find(">= 0") != std::string::npos ||
                         type.find(">= 1") != std::string::npos ||
                         type.find("> 0") != std::string::npos ||
                         std::regex_search(type, std::regex("(^| )[0-9.]+\\.\\."));
    // Clamped into 0..1 with a warning instead (CheckKeying; test AdjustmentsAreReported).
    if (!bounded || key == "keying.despill.strength") continue;
    // The key as nested YAML, one level an indent.
    std::string yaml, indent;
    size_t at = 0;
    for (size_t dot; (dot = key.find('.', at)) != std::string::npos; at = dot + 1) {
      yaml += indent + key.substr(at, dot - at) + ":\n";
      indent += "  ";
    }
    yaml += indent + key.substr(at) + ": -1\n";
    const std::string error = ErrorOf(yaml);
    const int line_of_key = static_cast<int>(std::count(yaml.begin(), yaml.end(), '\n'));
    EXPECT_EQ(error.rfind("station.yaml:" + std::to_string(line_of_key) + ": " + key + ": ", 0), 0u)
        << key << " (" << type << "): " << error;
    ++checked[key.substr(0, key.find('.'))];
  }
  EXPECT_GE(checked["pipeline"], 18);
  EXPECT_GE(checked["transitions"], 1);
  EXPECT_GE(checked["storage"], 1);
}

// The noise rule's thresholds (issue 19): shares from 0 to 1, 0 turning a test off.
TEST(StationConfig, NoiseThresholds) {
  const StationConfig cfg = Parse(
      "pipeline:\n  noise_min_solidity: 0\n  noise_recover_solidity: 0.4\n  noise_thick_px: 3\n"
      "  noise_min_thick_share: 0.2\n  noise_min_largest_share: 0.5\n  noise_min_mean_alpha: "
      "0.6\n");
  EXPECT_EQ(cfg.pipeline.noise.min_solidity, 0);
  EXPECT_EQ(cfg.pipeline.noise.recover_solidity, 0.4);
  EXPECT_EQ(cfg.pipeline.noise.thick_px, 3);
  EXPECT_EQ(cfg.pipeline.noise.min_thick_share, 0.2);
  EXPECT_EQ(cfg.pipeline.noise.min_largest_share, 0.5);
  EXPECT_EQ(cfg.pipeline.noise.min_mean_alpha, 0.6);
  const std::string share = ErrorOf("pipeline:\n  noise_min_solidity: 1.5\n");
  EXPECT_NE(share.find("pipeline.noise_min_solidity: expected a share from 0 to 1"),
            std::string::npos)
      << share;
  EXPECT_NE(ErrorOf("pipeline:\n  noise_thick_px: -1\n").find("pipeline.noise_thick_px"),
            std::string::npos);
}

// transitions.include_merged: off by default (merged sprites take no part), a boolean.
TEST(StationConfig, TransitionsIncludeMerged) {
  EXPECT_FALSE(Parse("version: 1\n").transitions.include_merged);
  EXPECT_TRUE(Parse("transitions:\n  include_merged: true\n").transitions.include_merged);
  const std::string wrong = ErrorOf("transitions:\n  include_merged: sometimes\n");
  EXPECT_NE(wrong.find("transitions.include_merged"), std::string::npos) << wrong;
  const std::string unknown = ErrorOf("transitions:\n  include_merge: true\n");
  EXPECT_NE(unknown.find("transitions.include_merge"), std::string::npos) << unknown;
}

// transitions.max_per_sprite: 100 by default, 0 (every transition) or more, refused at its key.
TEST(StationConfig, TransitionsMaxPerSprite) {
  EXPECT_EQ(Parse("version: 1\n").transitions.max_per_sprite, 100);
  EXPECT_EQ(Parse("transitions:\n  max_per_sprite: 0\n").transitions.max_per_sprite, 0);
  const std::string negative = ErrorOf("transitions:\n  max_per_sprite: -1\n");
  EXPECT_NE(negative.find("transitions.max_per_sprite"), std::string::npos) << negative;
  EXPECT_NE(negative.find(":2:"), std::string::npos) << negative;  // FILE:LINE of the key
}

TEST(StationConfig, SyntaxErrorsAndBadFiles) {
  const std::string msg = ErrorOf("cameras:\n  - name: [unclosed\n");
  EXPECT_EQ(msg.rfind("station.yaml:", 0), 0u) << msg;
  EXPECT_NE(msg.find("not valid YAML"), std::string::npos) << msg;
  EXPECT_EQ(
      ErrorOf(""),
      "station.yaml: the config is empty (expected sections such as cameras, enclosure, storage)");
  EXPECT_EQ(ErrorOf("- a\n- b\n"),
            "station.yaml:1: (top level): expected a mapping of keys, got a list");

  ScratchDir dir;
  try {
    LoadStationConfig(dir / "missing.yaml");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind(dir / "missing.yaml" + ": cannot open the config", 0), 0u)
        << e.what();
  }
}

// Issue 39: `config check` says what the daemon will do. Each of these was valid, and the
// daemon then failed (bad_alloc on every frame, a refusal to start, a 20 MB message).
TEST(StationConfig, ValuesTheDaemonCannotHoldAreRefused) {
  const std::string cam = "cameras:\n  - name: c\n    source: v4l2\n    device: /dev/video0\n";
  // The training set against its memory budget (a camera of unset size counts as 1920x1080).
  EXPECT_EQ(
      ErrorOf(cam + "keying:\n  training_frames: 2000000000\n"),
      "station.yaml:6: keying.training_frames: expected at most 172 frames: 2000000000 frames "
      "of 1920x1080 take 11587142.9 GiB, and a camera's training set may hold 1 GiB (1000 frames "
      "at most)");
  EXPECT_EQ(ErrorOf(cam + "    width: 3840\n    height: 2160\nkeying:\n  training_frames: 44\n"),
            "station.yaml:8: keying.training_frames: expected at most 43 frames: 44 frames of "
            "3840x2160 take 1.0 GiB, and a camera's training set may hold 1 GiB (1000 frames at "
            "most)");
  EXPECT_EQ(Parse(cam + "keying:\n  training_frames: 172\n").pipeline.keying->training_frames, 172);
  // A camera's name: at most 64 characters, and the message does not repeat a long one.
  const std::string long_name(1 << 20, 'a');  // the e2e test has the 10 MiB one
  EXPECT_EQ(ErrorOf("cameras:\n  - name: " + long_name + "\n    source: v4l2\n    device: x\n"),
            "station.yaml:2: cameras[0].name: expected a name of at most 64 characters, got "
            "1048576");
  EXPECT_EQ(ErrorOf("cameras:\n  - name: " + std::string(100, '/') +
                    "\n    source: v4l2\n"
                    "    device: x\n"),
            "station.yaml:2: cameras[0].name: expected a name of at most 64 characters, got 100");
  EXPECT_EQ(ErrorOf("cameras:\n  - name: a/b\n    source: v4l2\n    device: x\n"),
            "station.yaml:2: cameras[0].name: expected letters, digits, '_', '-' or '.', got "
            "\"a/b\"");
  // Any long value is quoted in part, with its length (core/yaml_reader.h, Quoted).
  EXPECT_EQ(ErrorOf(cam + "    fps: " + std::string(100, 'f') + "\n"),
            "station.yaml:5: cameras[0].fps: expected a positive number, got \"" +
                std::string(64, 'f') + "...\" (100 characters)");
  // No cameras at all: replay and ingest did nothing and exited 0.
  EXPECT_EQ(ErrorOf("cameras: []\n"), "station.yaml:1: cameras: expected at least one camera");
  // The bank: a folder or a device, in the words the daemon refuses it with.
  ScratchDir dir;
  ConfigOptions files;
  files.check_files = true;
  EXPECT_EQ(ErrorOf("storage:\n  bank: /dev/null\n", files),
            "station.yaml:2: storage.bank: /dev/null: not a sprite bank (not a regular file)");
  fs::create_directories(dir / "banks");
  EXPECT_EQ(ErrorOf("storage:\n  bank: " + (dir / "banks") + "\n", files),
            "station.yaml:2: storage.bank: " + (dir / "banks") + ": not a sprite bank (a folder)");
  try {
    OpenBankDatabase("/dev/null", true);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "/dev/null: not a sprite bank (not a regular file)");
  }
}

// Issue 39: one YAML document, nested no deeper than yaml-cpp reads, each said so (a second
// document was dropped without a word; deep nesting was "bad file").
TEST(StationConfig, OneDocumentOfBoundedDepth) {
  EXPECT_EQ(ErrorOf("version: 1\n---\ncameras: 3\n"),
            "station.yaml:2: a second YAML document (---) starts here; the file must hold one "
            "document");
  EXPECT_EQ(ErrorOf("---\nversion: 1\n---\n"),
            "station.yaml:3: a second YAML document (---) starts here; the file must hold one "
            "document");
  EXPECT_EQ(ErrorOf("version: 1\nlogging:\n  level: " + std::string(600, '[') +
                    std::string(600, ']') + "\n"),
            "station.yaml:3: nested deeper than 499 levels");
}

TEST(StationConfig, FilesAreCheckedWhenAsked) {
  ScratchDir dir;
  const std::string yaml =
      "cameras:\n  - name: cam0\n    source: replay\n    session: s1\n    model: "
      "cam0.cameramodel\n";
  std::ofstream(dir / "station.yaml") << yaml;
  try {
    LoadStationConfig(dir / "station.yaml");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    const std::string path = dir / "station.yaml";
    EXPECT_EQ(std::string(e.what()), path + ":4: cameras[0].session: " + (dir / "s1/session.json") +
                                         ": no such recorded session (session.json)\n" + path +
                                         ":5: cameras[0].model: " + (dir / "cam0.cameramodel") +
                                         ": no such camera model");
  }
  fs::create_directories(dir / "s1");
  std::ofstream(dir / "s1/session.json") << "{}";
  std::ofstream(dir / "cam0.cameramodel") << "{}";
  const StationConfig cfg = LoadStationConfig(dir / "station.yaml");
  EXPECT_EQ(cfg.cameras[0].backend.Get<ReplayCameraKeys>().session, dir / "s1");
  EXPECT_EQ(cfg.cameras[0].model, dir / "cam0.cameramodel");
}

TEST(StationConfig, AdjustmentsAreReported) {
  ConfigReport report;
  const StationConfig cfg = Parse(
      "cameras:\n  - {name: c, source: v4l2, device: /dev/video0, pixel_format: nv12, width: 1281, "
      "height: 721}\n"
      "keying:\n  despill: {strength: 1.5}\n"
      "storage:\n  stop_recording_below_mib: 100\n  stop_sprites_below_mib: 500\n",
      &report);
  EXPECT_EQ(report.status, ConfigStatus::kAdjusted);
  EXPECT_EQ(cfg.cameras[0].width, 1280);
  EXPECT_EQ(cfg.cameras[0].height, 720);
  EXPECT_EQ(cfg.pipeline.keying->despill.strength, 1.0);
  EXPECT_EQ(cfg.storage.stop_recording_below_mib, 500);
  EXPECT_EQ(cfg.storage.stop_sprites_below_mib, 500);
  ASSERT_EQ(report.adjustments.size(), 4u) << report.Summary();
  EXPECT_EQ(
      report.adjustments[0],
      "station.yaml:2: cameras[0].width: 1281 is odd, which nv12 cannot carry; lowered to 1280");
  EXPECT_EQ(report.adjustments[2],
            "station.yaml:4: keying.despill.strength: 1.5 is outside 0..1; clamped to 1");
  EXPECT_EQ(report.adjustments[3],
            "station.yaml:6: storage.stop_recording_below_mib: 100 is below "
            "stop_sprites_below_mib; raised to 500 so "
            "that raw recording stops before sprite storage");
  // Validating the adjusted config again finds nothing left to adjust.
  StationConfig again = cfg;
  EXPECT_EQ(ValidateStationConfig(again, "again", {}, NoFileChecks()).status, ConfigStatus::kValid);
  EXPECT_EQ(again, cfg);
}

TEST(StationConfig, TokenRequiredAwayFromLoopback) {
  EXPECT_EQ(ErrorOf("control:\n  address: 0.0.0.0\n"),
            "station.yaml:2: control.token: required when control.address (0.0.0.0) is not "
            "loopback; set token or "
            "token_file");
  EXPECT_EQ(ErrorOf("control:\n  address: 192.168.1.5\n  token: short\n"),
            "station.yaml:3: control.token: too short: use at least 16 characters (got 5)");
  EXPECT_EQ(ErrorOf("control:\n  address: studio-host\n"),
            "station.yaml:2: control.address: expected an IP address (or localhost), got "
            "\"studio-host\"");
  EXPECT_EQ(Parse("control:\n  address: 0.0.0.0\n  token: 0123456789abcdef\n").control.token,
            "0123456789abcdef");
  EXPECT_EQ(Parse("control:\n  address: 127.0.0.2\n").control.token, "");
  EXPECT_EQ(Parse("control:\n  address: '::1'\n").control.address, "::1");
  EXPECT_EQ(Parse("control:\n  address: localhost\n  port: 0\n").control.port, 0);

  ScratchDir dir;
  std::ofstream(dir / "token") << "s3cret-s3cret-s3cret\n";
  std::ofstream(dir / "station.yaml") << "control:\n  address: '::'\n  token_file: token\n";
  EXPECT_EQ(LoadStationConfig(dir / "station.yaml").control.token, "s3cret-s3cret-s3cret");
  std::ofstream(dir / "station.yaml") << "control:\n  address: '::'\n  token_file: nope\n";
  EXPECT_THROW(LoadStationConfig(dir / "station.yaml"), InputError);
}

TEST(StationConfig, LoopbackAddresses) {
  EXPECT_TRUE(IsLoopbackAddress("127.0.0.1"));
  EXPECT_TRUE(IsLoopbackAddress("127.10.0.1"));
  EXPECT_TRUE(IsLoopbackAddress("::1"));
  EXPECT_TRUE(IsLoopbackAddress("::ffff:127.0.0.1"));
  EXPECT_TRUE(IsLoopbackAddress("localhost"));
  EXPECT_FALSE(IsLoopbackAddress("0.0.0.0"));
  EXPECT_FALSE(IsLoopbackAddress("::"));
  EXPECT_FALSE(IsLoopbackAddress("10.0.0.1"));
  EXPECT_FALSE(IsLoopbackAddress("128.0.0.1"));
  EXPECT_FALSE(IsLoopbackAddress("127.0.0.1.evil.com"));
}

TEST(StationConfig, ValidatesConfigsBuiltInCode) {
  StationConfig cfg;
  cfg.storage.bank = "/b";
  cfg.storage.recording_dir = "/r";
  EXPECT_EQ(ValidateStationConfig(cfg, "code", {}, NoFileChecks()).status, ConfigStatus::kValid);
  cfg.pipeline.rectify.px_per_m = -5;
  cfg.control.address = "0.0.0.0";
  const ConfigReport report = ValidateStationConfig(cfg, "code", {}, NoFileChecks());
  EXPECT_EQ(report.status, ConfigStatus::kInvalid);
  ASSERT_EQ(report.errors.size(), 2u);
  EXPECT_EQ(report.errors[0],
            "code: pipeline.px_per_m: expected auto or a positive number, got -5");
  EXPECT_EQ(report.errors[1].rfind("code: control.token: required", 0), 0u) << report.errors[1];
}

// A number's bounds are its binding's (config_keys.cc, .Rule): checked on a config built in
// code as on one read from a file, in the binding's words, and written into the docs' type.
TEST(StationConfig, BoundsAreTheKeysOwnWhereverTheValuesComeFrom) {
  StationConfig cfg;
  cfg.storage.bank = "/b";
  cfg.storage.recording_dir = "/r";
  CameraConfig cam;
  cam.name = "c";
  cam.source = "v4l2";
  cam.backend.Use<V4l2CameraKeys>().device = "/dev/video0";
  cam.fps = -1;
  cam.gain_db = -2;
  cam.white_balance.red_gain = 0;
  cfg.cameras.push_back(cam);
  cfg.pipeline.keying.emplace();
  cfg.pipeline.keying->Block<ChromaKeyBlock>("chroma").low = 300;
  cfg.storage.spool_max_mib = 0;
  cfg.control.port = 70000;
  const ConfigReport report = ValidateStationConfig(cfg, "code", {}, NoFileChecks());
  const std::vector<std::string> want = {
      "code: cameras[0].fps: expected a positive number, got -1",
      "code: cameras[0].gain_db: expected a number >= 0, got -2",
      "code: cameras[0].white_balance.red_gain: expected a positive number, got 0",
      "code: keying.chroma.low: expected a level from 0 to 255, got 300",
      "code: storage.spool_max_mib: expected a size >= 1, got 0",
      "code: control.port: expected a port number 0..65535, got 70000"};
  EXPECT_EQ(report.errors, want);
  // The same values from a file: the same words, at their lines.
  const std::string from_file = ErrorOf(
      "cameras:\n  - name: c\n    source: v4l2\n    device: /dev/video0\n    fps: -1\n"
      "keying:\n  chroma:\n    low: 300\n");
  EXPECT_EQ(from_file,
            "station.yaml:5: cameras[0].fps: expected a positive number, got -1\n"
            "station.yaml:8: keying.chroma.low: expected a level from 0 to 255, got 300");
  // The docs' types say the same bounds.
  const std::string text = ConfigKeysText();
  for (const char* line :
       {"keying.chroma.low (number 0..255, ", "control.port (integer 0..65535, ",
        "storage.spool_max_mib (integer >= 1, ", "cameras[].white_balance.red_gain (number > 0, "})
    EXPECT_NE(text.find(line), std::string::npos) << line;
}

TEST(OptionsBinder, ANumbersRuleIsCheckedAtItsKeyOnceAndOnlyOnNumbers) {
  int frames = 0;
  double share = 2;
  std::optional<double> unset;
  std::string name;
  OptionsBinder b;
  b.Add("frames", &frames, "at least 1 frame", "frames")
      .Rule(AtLeast(1))
      .Add("block.share", &share, "a share from 0 to 1", "share")
      .Rule(Between(0, 1))
      .Add("gain", &unset, "a positive number", "gain")
      .Rule(Positive());
  EXPECT_THROW(b.Add("name", &name, "a string", "its name").Rule(Positive()), std::logic_error);
  std::map<std::string, int> lines = {{"top.frames", 3}};
  YamlMessages msg("f.yaml", lines);
  msg.Error("top.block.share", "read wrong");  // a key with an error already: not again
  b.CheckRules(msg, "top");
  EXPECT_EQ(msg.errors, (std::vector<std::string>{"f.yaml: top.block.share: read wrong",
                                                  "f.yaml:3: top.frames: expected at least 1 "
                                                  "frame, got 0"}));
  unset = 0;  // set, and out of bounds
  share = std::nan("");
  YamlMessages again("f.yaml", lines);
  b.CheckRules(again, "");
  ASSERT_EQ(again.errors.size(), 3u);
  EXPECT_EQ(again.errors[1], "f.yaml: block.share: expected a share from 0 to 1, got nan");
  EXPECT_EQ(again.errors[2], "f.yaml: gain: expected a positive number, got 0");
  EXPECT_EQ(AtLeast(1).Text(), ">= 1");
  EXPECT_EQ(Positive().Text(), "> 0");
  EXPECT_EQ(Between(0, 65535).Text(), "0..65535");
}

// The keys of the test's backend: a struct of its own, which capture/camera_config.h does not
// name.
struct TestcamKeys {
  std::string device;
  int lanes = 1;
  bool operator==(const TestcamKeys&) const = default;
};

// Registers a backend of its own, as a backend's file does, and reads configs naming it; the
// number of answers that were not as wanted (each printed).
int ReadConfigsOfARegisteredBackend() {
  RegisterCameraBackend(
      {"testcam", "a backend of this test", nullptr, nullptr,
       [](OptionsBinder& keys, CameraConfig& camera) {
         auto& own = camera.backend.Use<TestcamKeys>();
         keys.Add("device", &own.device, "a string", "the test device")
             .Add("lanes", &own.lanes, "a lane count from 1 to 4", "the test's lanes")
             .Rule(Between(1, 4));
       },
       [](CameraConfig& camera, std::string* why) {
         const auto& own = camera.backend.Get<TestcamKeys>();
         OptionProblems check(why);
         check(own.device.rfind("/dev/", 0) == 0, "device",
               "expected a /dev path, got " + own.device);
         return check.ok();
       },
       [](const CameraConfig& camera) -> std::vector<CameraFile> {
         return {{"device", camera.backend.Get<TestcamKeys>().device, "test device"}};
       },
       nullptr, false});
  const std::string head = "cameras:\n  - name: t\n    source: testcam\n";
  const std::vector<std::pair<std::string, std::string>> errors = {
      {head + "    device: /dev/x\n", ""},
      {head + "    device: x\n", "station.yaml:4: cameras[0].device: expected a /dev path, got x"},
      {head + "    device: /dev/x\n    lanes: 5\n",
       "station.yaml:5: cameras[0].lanes: expected a lane count from 1 to 4, got 5"},
      {head + "    device: /dev/x\n    fps: 30\n",
       "station.yaml:5: cameras[0].fps: only for source aravis or libcamera or v4l2 (this "
       "camera's source is testcam)"},
      {"cameras:\n  - name: c\n    source: replay\n    session: s\n    device: /dev/x\n",
       "station.yaml:5: cameras[0].device: only for source testcam or v4l2 (this camera's "
       "source is replay)"}};
  int failed = 0;
  for (const auto& [yaml, error] : errors) {
    const std::string got = ErrorOf(yaml);
    if (got == error) continue;
    std::fprintf(stderr, "for\n%sgot    \"%s\"\nwanted \"%s\"\n", yaml.c_str(), got.c_str(),
                 error.c_str());
    ++failed;
  }
  // The files it names are checked when the config checks files.
  const std::string missing = ErrorOf(head + "    device: /dev/no-such-testcam\n", ConfigOptions{});
  if (missing != "station.yaml:4: cameras[0].device: /dev/no-such-testcam: no such test device") {
    std::fprintf(stderr, "for a missing device got \"%s\"\n", missing.c_str());
    ++failed;
  }
  // The block is the camera's: read, copied and compared with it.
  const StationConfig read = Parse(head + "    device: /dev/x\n    lanes: 3\n");
  const CameraConfig camera = read.cameras.at(0);
  if (camera.backend.Get<TestcamKeys>() != TestcamKeys{"/dev/x", 3}) ++failed;
  if (!(camera == read.cameras.at(0))) ++failed;
  CameraConfig other = camera;
  other.backend.Use<TestcamKeys>().lanes = 2;
  if (other == camera || read.cameras.at(0).backend.Get<TestcamKeys>().lanes != 3) ++failed;
  return failed;
}

// A backend owns its keys and their rules (capture/camera_backend.h): one registered as a
// backend's own file does is read and checked by the config without a line of config/. It is
// registered in a child process, so that the other tests see only the backends built in.
TEST(StationConfigDeathTest, ABackendBindsAndChecksItsOwnKeys) {
  // The death test's child runs one thread: exit's atexit handlers race with nothing.
  EXPECT_EXIT(std::exit(ReadConfigsOfARegisteredBackend()),  // NOLINT(concurrency-mt-unsafe)
              ::testing::ExitedWithCode(0), "");
}

std::string ReadText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// docs/config.md's key tables are the code's (config/config_keys.cc, the backends' keys): a key
// bound, renamed, documented anew or given another default without the doc rewritten fails here.
TEST(ConfigKeys, DocsConfigMdHoldsTheKeyTablesAsTheCodeBindsThem) {
  const std::string doc = ReadText(ss::testing::SourcePath("docs/config.md"));
  ASSERT_FALSE(doc.empty());
  EXPECT_EQ(WithConfigKeyTables(doc, "docs/config.md"), doc)
      << "docs/config.md is stale: run `spritestation config keys --update docs/config.md`";
  // Every key the reader takes is in a table: one the reader takes and the docs lack fails.
  for (const char* key : {"`training_frames`", "`chroma.low`", "`max_view_angle_deg`",
                          "`spool_max_mib`", "`packet_size`", "`session_camera`", "`token_file`"})
    EXPECT_NE(doc.find(key), std::string::npos) << key;
}

TEST(ConfigKeys, AStaleTableIsMadeAnewAndABrokenMarkerIsNamed) {
  const std::string tables = ConfigKeysMarkdown();
  const std::string doc = "# title\n\n" + tables + "\nafter\n";
  EXPECT_EQ(WithConfigKeyTables(doc, "d.md"), doc);
  // A row changed by hand, a row dropped: made anew.
  std::string stale = doc;
  const size_t row = stale.find("| `min_area_px` |");
  ASSERT_NE(row, std::string::npos);
  stale.replace(row, stale.find('\n', row) - row, "| `min_area_px` | integer | `1` | old |");
  EXPECT_NE(stale, doc);
  EXPECT_EQ(WithConfigKeyTables(stale, "d.md"), doc);
  // A table missing, a name unknown, a marker not closed: errors naming the file.
  const std::string begin = "<!-- generated by `spritestation config keys --markdown`: ";
  const auto error_of = [](const std::string& text) {
    try {
      WithConfigKeyTables(text, "d.md");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(error_of("# nothing\n").find("d.md: holds no key table \"top\""), std::string::npos);
  EXPECT_NE(error_of(doc + begin + "pipelines -->\n<!-- end of generated table -->\n")
                .find("d.md: no key table named \"pipelines\""),
            std::string::npos);
  EXPECT_NE(error_of(doc + begin + "pipeline -->\n").find("d.md: a generated table's marker"),
            std::string::npos);
}

// A key the docs cannot describe is the code's defect: binding it throws, naming the key.
TEST(ConfigKeys, AKeyWithoutDocOrTypeCannotBeBound) {
  int field = 0;
  OptionsBinder b;
  EXPECT_THROW(b.Add("n", &field, "a number", ""), std::logic_error);
  b.AddRead("shaped", "", "a shape of its own",
            [](YamlReader&, const YamlMap&, const std::string&) { return false; });
  try {
    b.Rows();
    ADD_FAILURE() << "a key without its type gave rows";
  } catch (const std::logic_error& e) {
    EXPECT_NE(std::string(e.what()).find("\"shaped\" bound without a type"), std::string::npos);
  }
  b.Type("a shape");
  ASSERT_EQ(b.Rows().size(), 1u);
  EXPECT_EQ(b.Rows()[0].type, "a shape");
}

// `config keys`: a line a key, with the blocks' paths; the defaults are the fields'.
TEST(ConfigKeys, TheListNamesEveryKeyWithItsDefault) {
  const std::string text = ConfigKeysText();
  for (const char* line :
       {"pipeline.min_area_px (integer >= 1, default `400`): ",
        "keying.method (`chroma` | `clean_plate`, default `chroma`): ",
        "storage.bank (path or `postgresql://…`, default `station.bank`): ",
        "cameras[].packet_size (integer: `0` or 576..16384, default `0`, sources aravis): ",
        "cameras[].white_balance.mode (`device` | `once` | `manual`, default `device`): "})
    EXPECT_NE(text.find(line), std::string::npos) << line << "\n" << text;
  EXPECT_EQ(text.find("see below"), std::string::npos) << "a block is not a key";
}

}  // namespace
}  // namespace ss
