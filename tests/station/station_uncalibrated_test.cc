// A station that lacks the floor (a first-time user's config names only cameras) starts all
// the same, so that the calibration wizard can find the floor: its camera is live for preview
// and recording, says what it lacks, and stores no sprite; `CalibrationGaps`, which `config
// check` prints, names the same gap.
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "capture/replay/replay_source.h"
#include "core/bank.h"
#include "station/station.h"
#include "station/station_status.h"
#include "tests/station/replay_station.h"
#include "tests/support/test_support.h"

namespace ss {
namespace {

using testing::OneReplayCamera;
using testing::WaitFor;
namespace fs = std::filesystem;

TEST(StationUncalibrated, WithoutAFloorTheStationStreamsAndStoresNoSprite) {
  testing::ScratchDir dir;
  StationOptions options = OneReplayCamera(dir);
  options.config.logging.level = "warn";
  // The session brings the floor its cameras saw (truth/floor.json): take it away.
  const fs::path session = options.config.cameras[0].backend.Get<ReplayCameraKeys>().session;
  ASSERT_TRUE(fs::remove(session / "truth" / "floor.json"));
  ASSERT_TRUE(StationFloor(options.config).empty());
  const std::vector<std::string> gaps = CalibrationGaps(options.config);
  EXPECT_TRUE(testing::AnyContains(gaps, "enclosure.floor")) << "gaps: " << gaps.size();
  EXPECT_FALSE(testing::AnyContains(gaps, "cam0")) << "the session's camera model is there";

  Station station(options);  // no InputError: the wizard needs the station running
  station.Start();
  ASSERT_TRUE(WaitFor(
      station,
      [](const StationStatus& s) {
        return s.cameras.size() == 1 && s.cameras[0].state == CameraState::kLive &&
               s.cameras[0].frames_captured > 30;
      },
      30))
      << StatusToJson(station.Status()).dump(2);
  const CameraStatus cam = station.Status().cameras[0];
  EXPECT_TRUE(cam.has_model);
  EXPECT_FALSE(cam.has_floor);
  EXPECT_NE(cam.message.find("no floor"), std::string::npos) << cam.message;

  // A session of 2.5 s, in which the animal walks: nothing is stored without the floor.
  station.StartSession("no floor");
  const uint64_t frames = station.Status().cameras[0].frames_captured;
  ASSERT_TRUE(WaitFor(
      station, [&](const StationStatus& s) { return s.cameras[0].frames_captured > frames + 75; },
      30));
  const SessionStatus stopped = station.StopSession();
  EXPECT_EQ(stopped.sprites_stored, 0u);
  station.Stop();
  EXPECT_EQ(Bank(options.config.storage.bank).Counts().sprites, 0);
}

TEST(StationUncalibrated, TheSessionsFloorIsTheStationsAndNoGapIsNamed) {
  testing::ScratchDir dir;
  const StationOptions options = OneReplayCamera(dir);
  EXPECT_FALSE(StationFloor(options.config).empty()) << "the session's truth/floor.json";
  EXPECT_TRUE(CalibrationGaps(options.config).empty());
}

}  // namespace
}  // namespace ss
