// End to end: `spritestation import` on videos made here with the ffmpeg CLI, whose
// frames, times and background are known: frame count, the container's timestamps
// (a variable frame rate kept), the empty scene made by the per-pixel median, and
// the errors a user can cause (docs/import.md).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "capture/recording/video_reader.h"
#include "core/session.h"
#include "tests/support/test_support.h"

namespace ss {
namespace {

namespace fs = std::filesystem;
using testing::JsonInOutput;
using testing::RunCommand;
using testing::RunSpritestation;
using testing::ScratchDir;

constexpr int kFrames = 100;             // 4 s at 25 fps
constexpr int64_t kGapNs = 200'000'000;  // added before frame 50: a variable frame rate
// The background, BGR, of 0x305070; a light-grey 30x60 box crosses it at 60 px/s,
// so it covers any one pixel for half a second of the four.
const int kBackground[3] = {0x70, 0x50, 0x30};

const char* kRough = " --camera-height 3 --tilt 30 --hfov 60";

class ImportVideo : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new ScratchDir();
    // H.264 with B-frames (decode order is not presentation order), frames 1/25 s apart except
    // one gap of 0.24 s: the pts the container carries are the only record of it.
    const auto r = RunCommand(
        "ffmpeg -v error -y -f lavfi -i color=c=0x305070:s=320x240:r=25:d=4 "
        "-f lavfi -i color=c=0xE0E0E0:s=30x60:r=25:d=4 -filter_complex "
        "\"[0][1]overlay=x='20+t*60':y=100,setpts='N/(25*TB)+gte(N\\,50)*0.2/TB'\" "
        "-fps_mode passthrough -c:v libx264 -g 10 -bf 2 -pix_fmt yuv420p " +
        *dir_ / "walk.mp4");
    ASSERT_EQ(r.exit_code, 0) << r.output;
  }
  static void TearDownTestSuite() { delete dir_; }
  static int64_t TrueTimestampNs(int frame) {
    return frame * 40'000'000LL + (frame >= 50 ? kGapNs : 0);
  }
  static ScratchDir* dir_;
};
ScratchDir* ImportVideo::dir_ = nullptr;

// The largest difference from the background over a frame's pixels, in levels.
int MaxDifferenceFromBackground(const std::vector<uint8_t>& bgr) {
  int worst = 0;
  for (size_t i = 0; i < bgr.size(); ++i)
    worst = std::max(worst, std::abs(int{bgr[i]} - kBackground[i % 3]));
  return worst;
}

TEST_F(ImportVideo, KeepsEveryFrameWithTheContainersTimes) {
  const std::string out = *dir_ / "all";
  const auto r = RunSpritestation("--log-level warn import " + *dir_ / "walk.mp4" + " --out " +
                                  out + kRough + " --codec ffvhuff --json");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json j = JsonInOutput(r.output);
  ASSERT_EQ(j["cameras"].size(), 1u) << r.output;
  EXPECT_EQ(j["cameras"][0]["frames"], kFrames);
  EXPECT_EQ(j["cameras"][0]["empty_frames"], 30);

  const SessionInfo info = ReadSessionInfo(out);
  ASSERT_EQ(info.cameras.size(), 1u);
  EXPECT_EQ(info.cameras[0].width, 320);
  EXPECT_EQ(info.cameras[0].height, 240);
  EXPECT_EQ(info.cameras[0].frames, 30 + kFrames);
  EXPECT_FALSE(info.cameras[0].model.empty());
  const std::vector<FrameRecord> rows = ReadFrameCsv(out + "/" + info.cameras[0].frames_csv);
  ASSERT_EQ(rows.size(), 30u + kFrames);
  for (int i = 0; i < kFrames; ++i) {
    EXPECT_EQ(rows[30 + i].timestamp_ns, TrueTimestampNs(i)) << "frame " << i;
    EXPECT_EQ(rows[30 + i].sequence, 30u + i);  // consecutive: no frame was lost
  }
  // The empty scene comes first, a nominal frame apart, before the first frame's time.
  for (int i = 0; i < 30; ++i) EXPECT_LT(rows[i].timestamp_ns, rows[i + 1].timestamp_ns) << i;
  // What ingest needs beside the session.
  EXPECT_TRUE(fs::exists(out + "/enclosure.json"));
  std::ifstream yaml(out + "/ingest.yaml");
  const std::string text((std::istreambuf_iterator<char>(yaml)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("method: clean_plate"), std::string::npos) << text;
  EXPECT_NE(text.find("training_frames: 30"), std::string::npos) << text;
  const auto config = RunSpritestation("--log-level warn config check " + out + "/ingest.yaml");
  EXPECT_EQ(config.exit_code, 0) << config.output;
}

// Issue 38: a camera looking straight down films from above: ingest stores its subjects as floor
// sprites, and import says so, where an oblique camera gets no word.
TEST_F(ImportVideo, ACameraThatSeesItsFloorOnlyFromAboveIsNamed) {
  auto r = RunSpritestation("--log-level warn import " + *dir_ / "walk.mp4" + " --out " +
                            *dir_ / "oblique" + kRough + " --codec ffvhuff --range 0-0.5 --json");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  // 3 m up, its floor out to 15 m: the far edge is seen atan(3 / 15) = 11 degrees above it
  const auto oblique = JsonInOutput(r.output)["cameras"][0];
  EXPECT_GT(oblique["shallowest_view_deg"].get<double>(), 5);
  EXPECT_LT(oblique["shallowest_view_deg"].get<double>(), 20);
  EXPECT_EQ(oblique["sprites"], "upright");
  // 0.6 m straight above, 20 degrees wide: its floor's corners are seen from 77 degrees
  r = RunSpritestation(
      "--log-level warn import " + *dir_ / "walk.mp4" + " --out " +
      *dir_ / "above --camera-height 0.6 --tilt 89 --hfov 20 --codec ffvhuff --range 0-0.5");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("cam0: films its floor from above (a median view of 8"),
            std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("steeper than pipeline.floor_view_angle_deg 65): ingest will store floor "
                          "sprites"),
            std::string::npos)
      << r.output;
  EXPECT_EQ(r.output.find("view_too_steep"), std::string::npos) << r.output;
}

TEST_F(ImportVideo, TheMedianPlateHoldsTheBackgroundWithoutTheWalker) {
  const std::string out = *dir_ / "median";
  const auto r = RunSpritestation("--log-level warn import " + *dir_ / "walk.mp4" + " --out " +
                                  out + kRough + " --codec ffvhuff --empty-frames 10");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const SessionInfo info = ReadSessionInfo(out);
  VideoReader reader(out + "/" + info.cameras[0].video, PixelFormat::kBGR8, 320, 240);
  std::vector<uint8_t> pixels;
  for (int i = 0; i < 10; ++i) {
    ASSERT_EQ(reader.Next(pixels).status, VideoReader::Status::kFrame);
    // H.264 at 4:2:0 moves a flat colour by a few levels; the box (0xE0) is 100+ away.
    EXPECT_LE(MaxDifferenceFromBackground(pixels), 6) << "empty-scene frame " << i;
  }
  // And the walker is in the imported frames: frame 0 has the box at x = 20..49, y = 100..159.
  ASSERT_EQ(reader.Next(pixels).status, VideoReader::Status::kFrame);
  EXPECT_GT(MaxDifferenceFromBackground(pixels), 100);
  const size_t inside = (130 * 320 + 35) * 3;
  EXPECT_GT(pixels[inside], 200);
}

TEST_F(ImportVideo, ATimeRangeKeepsItsFramesAndTheirTimes) {
  const std::string out = *dir_ / "range";
  // What a killed import of the same --out left (its process, beyond any pid_max, is gone).
  const std::string abandoned = *dir_ / ".range.import-99999999";
  fs::create_directories(abandoned);
  std::ofstream(abandoned + "/cam0.mkv") << "half a video";
  const auto r = RunSpritestation(
      "--log-level warn import " + *dir_ / "walk.mp4" + " --out " + out + kRough +
      " --codec ffvhuff --range 1.9-2.5 --empty-range 0-4 --empty-frames 5 --json");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::vector<FrameRecord> rows = ReadFrameCsv(out + "/cam0.frames.csv");
  // 1.92, 1.96, then the gap, 2.20 .. 2.48: frames 48..57.
  ASSERT_EQ(rows.size(), 5u + 10u);
  for (int i = 0; i < 10; ++i) EXPECT_EQ(rows[5 + i].timestamp_ns, TrueTimestampNs(48 + i)) << i;
  EXPECT_EQ(JsonInOutput(r.output)["empty_scene"], "range 0-4");
  EXPECT_FALSE(fs::exists(abandoned)) << "an abandoned import is cleared away";
}

TEST_F(ImportVideo, TwoVideosAreTwoCamerasWithTheirModelsAndAnEmptyClip) {
  // A model of the right size: the one a rough import wrote.
  const std::string first = *dir_ / "for_model";
  ASSERT_EQ(RunSpritestation("--log-level warn import " + *dir_ / "walk.mp4" + " --out " + first +
                             kRough + " --codec ffvhuff --range 0-0.5 --empty-frames 3")
                .exit_code,
            0);
  const std::string model = first + "/cam0.cameramodel";
  std::ofstream(*dir_ / "floor.json") << "{\"floor\": [[-3, 2], [3, 2], [3, 9], [-3, 9]]}\n";
  // The empty scene from a separate clip: the background alone, a second of it.
  ASSERT_EQ(
      RunCommand("ffmpeg -v error -y -f lavfi -i color=c=0x305070:s=320x240:r=25:d=1 -c:v libx264 "
                 "-pix_fmt yuv420p " +
                 *dir_ / "empty.mp4")
          .exit_code,
      0);
  const std::string out = *dir_ / "two";
  const auto r = RunSpritestation(
      "--log-level warn import " + *dir_ / "walk.mp4" + " " + *dir_ / "walk.mp4" + " --out " + out +
      " --model " + model + " --model " + model + " --floor " + *dir_ / "floor.json" +
      " --empty-clip " + *dir_ / "empty.mp4" + " --empty-clip " + *dir_ / "empty.mp4" +
      " --empty-frames 20 --range 0-1 --codec ffvhuff --json");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const SessionInfo info = ReadSessionInfo(out);
  ASSERT_EQ(info.cameras.size(), 2u);
  EXPECT_EQ(info.cameras[0].name, "cam0");
  EXPECT_EQ(info.cameras[1].name, "cam1");
  for (const SessionCamera& cam : info.cameras) {
    EXPECT_EQ(cam.frames, 20 + 25) << cam.name;
    EXPECT_FALSE(cam.model.empty()) << cam.name;
    VideoReader reader(out + "/" + cam.video, PixelFormat::kBGR8, 320, 240);
    std::vector<uint8_t> pixels;
    ASSERT_EQ(reader.Next(pixels).status, VideoReader::Status::kFrame);
    EXPECT_LE(MaxDifferenceFromBackground(pixels), 6) << cam.name << ": the clip's empty scene";
  }
  std::ifstream enclosure(out + "/enclosure.json");
  const nlohmann::json floor = nlohmann::json::parse(enclosure);
  EXPECT_EQ(floor["floor"].size(), 4u);
  EXPECT_EQ(JsonInOutput(r.output)["empty_scene"], "clip");
  // Several cameras share one floor: without --floor the import refuses.
  const auto no_floor =
      RunSpritestation("--log-level warn import " + *dir_ / "walk.mp4" + " " + *dir_ / "walk.mp4" +
                       " --out " + *dir_ / "two_b" + " --model " + model + " --model " + model);
  EXPECT_EQ(no_floor.exit_code, 2);
  EXPECT_NE(no_floor.output.find("--floor"), std::string::npos) << no_floor.output;
}

// A phone's portrait video: landscape frames and a display matrix that turns them. The import
// shows them as a player does; the ffmpeg CLI (which turns them too) is the reference.
TEST_F(ImportVideo, APortraitPhoneVideoComesTurnedAsAPlayerShowsIt) {
  const std::string mov = *dir_ / "portrait.mov";
  ASSERT_EQ(RunCommand("ffmpeg -v error -y -i " + *dir_ / "walk.mp4" +
                       " -c copy -metadata:s:v:0 rotate=90 " + mov)
                .exit_code,
            0);
  const std::string out = *dir_ / "portrait";
  const auto r =
      RunSpritestation("--log-level warn import " + mov + " --out " + out +
                       " --no-model --empty-frames 0 --range 0-0.2 --codec ffvhuff --json");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const SessionInfo info = ReadSessionInfo(out);
  EXPECT_EQ(info.cameras[0].width, 240);
  EXPECT_EQ(info.cameras[0].height, 320);
  const std::string raw = *dir_ / "portrait.bgr";
  ASSERT_EQ(
      RunCommand("ffmpeg -v error -y -i " + mov + " -frames:v 1 -f rawvideo -pix_fmt bgr24 " + raw)
          .exit_code,
      0);
  std::ifstream in(raw, std::ios::binary);
  const std::vector<uint8_t> shown((std::istreambuf_iterator<char>(in)),
                                   std::istreambuf_iterator<char>());
  VideoReader reader(out + "/" + info.cameras[0].video, PixelFormat::kBGR8, 240, 320);
  std::vector<uint8_t> pixels;
  ASSERT_EQ(reader.Next(pixels).status, VideoReader::Status::kFrame);
  ASSERT_EQ(pixels.size(), shown.size());
  int worst = 0;
  for (size_t i = 0; i < pixels.size(); ++i)
    worst = std::max(worst, std::abs(pixels[i] - shown[i]));
  EXPECT_LE(worst, 2);
}

TEST_F(ImportVideo, RefusesWhatItCannotUseNamingTheFileOrFlag) {
  const std::string video = *dir_ / "walk.mp4";
  const auto expect_refusal = [](const std::string& args, const std::string& named) {
    const auto r = RunSpritestation("--log-level warn import " + args);
    EXPECT_EQ(r.exit_code, 2) << args << "\n" << r.output;
    EXPECT_NE(r.output.find(named), std::string::npos) << args << "\n" << r.output;
  };
  expect_refusal(*dir_ / "missing.mp4" + " --out " + *dir_ / "x" + kRough,
                 "missing.mp4: no such file");
  std::ofstream(*dir_ / "garbage.mp4") << std::string(5000, 'x');
  expect_refusal(*dir_ / "garbage.mp4" + " --out " + *dir_ / "x" + kRough,
                 "garbage.mp4: FFmpeg cannot");
  expect_refusal(video + " --out " + *dir_ / "x" + kRough + " --range 10-20",
                 "--range: starts at 10 s");
  expect_refusal(video + " --out " + *dir_ / "x" + kRough + " --range 1-9", "--range: ends at 9 s");
  expect_refusal(video + " --out " + *dir_ / "x" + kRough + " --empty-range 0-0.2",
                 "--empty-range");
  expect_refusal(video + " --out " + *dir_ / "x", "--model");
  expect_refusal(video + " --out " + *dir_ / "x --camera-height 3 --tilt 30", "all three");
  expect_refusal(video + " --out " + *dir_ / "x --camera-height 3 --tilt -40 --hfov 60",
                 "sees no floor");
  expect_refusal(video + " --out " + *dir_ / "x" + kRough + " --codec png", "--codec");
  EXPECT_FALSE(fs::exists(*dir_ / "x")) << "a refused import leaves nothing behind";

  // An existing session is not replaced without --force; a folder that is not a session never.
  const std::string out = *dir_ / "existing";
  ASSERT_EQ(RunSpritestation("--log-level warn import " + video + " --out " + out + kRough +
                             " --codec ffvhuff --range 0-0.5 --empty-frames 3")
                .exit_code,
            0);
  const auto before = RunCommand("md5sum " + out + "/cam0.frames.csv");
  expect_refusal(video + " --out " + out + kRough + " --range 0-1", "give --force");
  EXPECT_EQ(RunCommand("md5sum " + out + "/cam0.frames.csv").output, before.output);
  const auto forced =
      RunSpritestation("--log-level warn import " + video + " --out " + out + kRough +
                       " --codec ffvhuff --range 0-1 --empty-frames 3 --force");
  EXPECT_EQ(forced.exit_code, 0) << forced.output;
  EXPECT_EQ(ReadFrameCsv(out + "/cam0.frames.csv").size(), 3u + 25u);
  fs::create_directories(*dir_ / "notes");
  std::ofstream(*dir_ / "notes/todo.txt") << "keep me\n";
  expect_refusal(video + " --out " + *dir_ / "notes" + kRough + " --force",
                 "not a recorded session");
  EXPECT_TRUE(fs::exists(*dir_ / "notes/todo.txt"));
  // No temporary folder is left beside the sessions.
  for (const auto& entry : fs::directory_iterator(dir_->path())) {
    EXPECT_EQ(entry.path().filename().string().find(".import-"), std::string::npos) << entry.path();
  }
}

}  // namespace
}  // namespace ss
