// Saving a calibration into a station's files: the config edited as text
// (comments kept), every file replaced atomically with the old one kept, and
// a folder that cannot be written changing nothing.
#include "config/station_save.h"

#include <sys/resource.h>
#include <unistd.h>

#include <csignal>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "config/station_config.h"
#include "core/error.h"
#include "synth/scene.h"
#include "tests/calib/calib_fixtures.h"
#include "tests/support/test_support.h"

namespace ss::calib {
namespace {

namespace fs = std::filesystem;
using ss::testing::ScratchDir;
using ss::testing::TrueModel;

std::string Read(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

void Write(const std::string& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
}

const char* kConfig =
    "version: 1\n"
    "# the studio's cameras\n"
    "cameras:\n"
    "  - name: left   # by the door\n"
    "    source: aravis\n"
    "    address: 127.0.0.1\n"
    "  - name: right\n"
    "    source: aravis\n"
    "    address: 127.0.0.2\n"
    "enclosure:\n"
    "  floor: [[-0.6, -0.4], [0.6, -0.4], [0.6, 0.4], [-0.6, 0.4]]\n";

CameraModel Model(int seed) {
  const synth::Studio studio = synth::MakeStudio(synth::StudioKind::kEnclosure, seed);
  return TrueModel(synth::MakeCameras(studio, 1, 640, 480, seed)[0]);
}

TEST(SetCameraModelPath, AddsOrReplacesTheKeyInTheCamerasEntryOnly) {
  std::string yaml = SetCameraModelPath(kConfig, "right", "/m/right.cameramodel", "station.yaml");
  EXPECT_NE(yaml.find("  - name: right\n    model: \"/m/right.cameramodel\"\n    source: aravis\n  "
                      "  address: 127.0.0.2"),
            std::string::npos)
      << yaml;
  EXPECT_NE(yaml.find("# the studio's cameras"), std::string::npos);
  EXPECT_NE(yaml.find("  - name: left   # by the door\n    source: aravis"), std::string::npos)
      << yaml;
  // Again: the key is replaced, not added twice.
  yaml = SetCameraModelPath(yaml, "right", "/m/new.cameramodel", "station.yaml");
  EXPECT_EQ(yaml.find("right.cameramodel"), std::string::npos) << yaml;
  EXPECT_EQ(yaml.find("model:"), yaml.rfind("model:"));
  yaml = SetCameraModelPath(yaml, "left", "/m/left.cameramodel", "station.yaml");
  EXPECT_NE(yaml.find("  - name: left   # by the door\n    model: \"/m/left.cameramodel\""),
            std::string::npos)
      << yaml;
  try {
    SetCameraModelPath(kConfig, "middle", "/m/x", "station.yaml");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("station.yaml"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("middle"), std::string::npos) << e.what();
  }
}

// A camera written as a flow mapping on one line (as a quick config is): the model is set in it,
// and the config loads with it (the console's Save once refused it: "no entry").
TEST(SetCameraModelPath, SetsTheKeyInAFlowMappingEntry) {
  const std::string config =
      "version: 1\ncameras:\n  - {name: cam0, source: replay, session: s}  # the left one\n"
      "  - {name: cam1, source: replay, session: s, session_camera: cam1, model: "
      "old.cameramodel}\n";
  std::string yaml = SetCameraModelPath(config, "cam1", "/m/cam1.cameramodel", "station.yaml");
  yaml = SetCameraModelPath(yaml, "cam0", "/m/cam0.cameramodel", "station.yaml");
  EXPECT_NE(yaml.find("  - {name: cam0, source: replay, session: s, model: /m/cam0.cameramodel}  "
                      "# the left one\n"),
            std::string::npos)
      << yaml;
  EXPECT_EQ(yaml.find("old.cameramodel"), std::string::npos) << yaml;
  const YAML::Node cameras = YAML::Load(yaml)["cameras"];
  EXPECT_EQ(cameras[0]["model"].as<std::string>(), "/m/cam0.cameramodel");
  EXPECT_EQ(cameras[1]["model"].as<std::string>(), "/m/cam1.cameramodel");
  EXPECT_EQ(cameras[1]["session_camera"].as<std::string>(), "cam1");
}

TEST(SaveStationCalibration, WritesModelsAndConfigAndKeepsWhatTheyReplace) {
  ScratchDir dir;
  const std::string config_path = dir / "station.yaml";
  Write(config_path, kConfig);
  const StationConfig config = LoadStationConfig(config_path);
  StationSaveRequest request;
  request.models = {{"left", Model(1)}};
  request.floor = GroundPolygon({{-0.5, -0.3}, {0.5, -0.3}, {0.5, 0.3}, {-0.5, 0.3}});
  request.config_path = config_path;
  request.calibration_dir = dir / "calibration";
  request.stamp = "20261202T070000Z";
  const StationSaveResult first = SaveStationCalibration(config, request);
  const std::string model_path = dir / "calibration/left.cameramodel";
  ASSERT_EQ(first.files.size(), 2u);
  EXPECT_EQ(first.files[0], model_path);
  EXPECT_EQ(first.previous,
            std::vector<std::string>{dir / "station.previous-20261202T070000Z.yaml"});
  EXPECT_EQ(Read(first.previous[0]), kConfig);
  // The saved config loads with the model and the floor; the other camera is as it was.
  const StationConfig saved = LoadStationConfig(config_path);
  EXPECT_EQ(saved.cameras[0].model, model_path);
  EXPECT_TRUE(saved.cameras[1].model.empty());
  EXPECT_NEAR(saved.enclosure.floor.Area(), 0.6, 1e-9);
  EXPECT_EQ(first.config.cameras[0].model, model_path);
  EXPECT_EQ(CameraModel::Read(model_path).intrinsics(), Model(1).intrinsics());

  // Saved again: the model it replaces is kept beside it, no temporary file is left.
  request.models = {{"left", Model(2)}};
  request.stamp = "20261202T080000Z";
  const StationSaveResult second = SaveStationCalibration(saved, request);
  EXPECT_EQ(CameraModel::Read(model_path).intrinsics(), Model(2).intrinsics());
  EXPECT_EQ(CameraModel::Read(dir / "calibration/left.previous-20261202T080000Z.cameramodel")
                .intrinsics(),
            Model(1).intrinsics());
  for (const auto& e : fs::recursive_directory_iterator(dir.path())) {
    EXPECT_EQ(e.path().string().find(".saving-"), std::string::npos) << e.path();
  }
}

// Root writes into read-only folders, so the faults are ones root meets too: the folder's
// path taken by a file, and a disk that takes no more bytes (RLIMIT_FSIZE).
TEST(SaveStationCalibration, AFolderThatCannotBeWrittenChangesNothing) {
  ScratchDir dir;
  const std::string config_path = dir / "station.yaml";
  Write(config_path, kConfig);
  StationSaveRequest request;
  request.models = {{"left", Model(1)}, {"right", Model(3)}};
  request.config_path = config_path;
  request.calibration_dir = dir / "calibration";
  request.stamp = "20261202T070000Z";
  SaveStationCalibration(LoadStationConfig(config_path), request);
  const std::string model_before = Read(dir / "calibration/left.cameramodel");
  const std::string config_before = Read(config_path);

  // The disk is full: the first new file cannot be written, so nothing is replaced.
  request.models = {{"left", Model(2)}, {"right", Model(4)}};
  request.floor = GroundPolygon({{-0.5, -0.3}, {0.5, -0.3}, {0.5, 0.3}, {-0.5, 0.3}});
  {
    std::signal(SIGXFSZ, SIG_IGN);
    rlimit old{};
    ::getrlimit(RLIMIT_FSIZE, &old);
    rlimit tiny = old;
    tiny.rlim_cur = 100;
    ::setrlimit(RLIMIT_FSIZE, &tiny);
    try {
      SaveStationCalibration(LoadStationConfig(config_path), request);
      ADD_FAILURE() << "saved onto a full disk";
    } catch (const WorkError& e) {
      EXPECT_NE(std::string(e.what()).find("left.cameramodel"), std::string::npos) << e.what();
    }
    ::setrlimit(RLIMIT_FSIZE, &old);
  }
  EXPECT_EQ(Read(dir / "calibration/left.cameramodel"), model_before);
  EXPECT_EQ(Read(config_path), config_before);
  for (const auto& e : fs::recursive_directory_iterator(dir.path())) {
    EXPECT_EQ(e.path().string().find(".saving-"), std::string::npos) << e.path();
  }

  // A camera whose model goes to a folder that cannot be made: named, nothing changed.
  Write(dir / "blocked", "a file where the folder should be\n");
  StationSaveRequest blocked = request;
  blocked.calibration_dir = dir / "blocked/calibration";
  Write(config_path, kConfig);  // no model paths: both go to the calibration folder
  try {
    SaveStationCalibration(LoadStationConfig(config_path), blocked);
    ADD_FAILURE() << "saved under a file";
  } catch (const WorkError& e) {
    EXPECT_NE(std::string(e.what()).find(dir / "blocked/calibration"), std::string::npos)
        << e.what();
  }
  EXPECT_EQ(Read(config_path), kConfig);
  // An unknown camera is named.
  request.models = {{"middle", Model(1)}};
  EXPECT_THROW(SaveStationCalibration(LoadStationConfig(config_path), request), InputError);
}

TEST(FloorPolygon, ReplacesTheConfigsFloorKeepingTheRest) {
  const std::string config =
      "version: 1\n"
      "# the enclosure\n"
      "enclosure:\n"
      "  floor:\n"
      "    - [-1.2, -0.8]\n"
      "    - [ 1.2, -0.8]\n"
      "    - [ 1.2,  0.8]\n"
      "  wall_height_m: 0.6   # keep me\n"
      "pipeline:\n"
      "  min_area_px: 500\n";
  const GroundPolygon floor({{-0.5, -0.3}, {0.5, -0.3}, {0.5, 0.3}, {-0.5, 0.3}});
  const std::string updated = ReplaceEnclosureFloor(config, floor, "station.yaml");
  ConfigOptions o;
  o.check_files = false;
  const StationConfig c = ParseStationConfig(updated, "station.yaml", ".", nullptr, o);
  ASSERT_EQ(c.enclosure.floor.vertices().size(), 4u);
  EXPECT_NEAR(c.enclosure.floor.Area(), 0.6, 1e-9);
  EXPECT_DOUBLE_EQ(c.pipeline.usability.wall_height_m, 0.6);
  EXPECT_EQ(c.pipeline.extract.min_area, 500);
  EXPECT_NE(updated.find("# keep me"), std::string::npos);
  // A config without an enclosure gets one.
  const StationConfig added = ParseStationConfig(
      ReplaceEnclosureFloor("version: 1\n", floor, "s.yaml"), "s.yaml", ".", nullptr, o);
  EXPECT_NEAR(added.enclosure.floor.Area(), 0.6, 1e-9);
}

}  // namespace
}  // namespace ss::calib
