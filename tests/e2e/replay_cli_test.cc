// `spritestation replay`: what it reports about a real recorded session, and
// how it treats a session whose camera model is missing or broken, whose video is cut
// short or whose frame CSV holds garbage (what the replay library makes of those two:
// tests/capture/replay_damage_test.cc).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "capture/recording/session_writer.h"
#include "capture/replay/replay_source.h"
#include "core/camera_model.h"
#include "core/error.h"
#include "core/session.h"
#include "tests/capture/session_fixtures.h"
#include "tests/support/test_support.h"

namespace ss {
namespace {

using ss::testing::RecordSessionWithGarbageCsv;
using ss::testing::RecordTruncatedSession;
using ss::testing::RunSpritestation;
using ss::testing::ScratchDir;
using ss::testing::TestCamera;
using ss::testing::TestFrame;

bool Contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// The JSON report inside the command's output (stderr's log lines and error come after it).
nlohmann::json JsonReport(const std::string& output) {
  const size_t begin = output.find("{\n");
  const size_t end = output.find("\n}", begin);
  if (begin == std::string::npos || end == std::string::npos) return nullptr;
  return nlohmann::json::parse(output.substr(begin, end + 2 - begin));
}

// Two cameras with known timing, sequence gaps and recorded drops:
//   wide: 10 frames every 40 ms from 2 s, sequences 0..4, 7..11 (a gap of 2; drops_before 2 at the
//   6th) tele: 5 frames every 100 ms from 2.01 s, sequences 50..54
// `model` gives `wide` a camera model.
void RecordKnownSession(const std::string& session, const CameraModel* model) {
  SessionWriter writer(session, "known");
  const int wide = writer.AddCamera(TestCamera("wide", PixelFormat::kBGR8, 64, 48, 25), model);
  const int tele = writer.AddCamera(TestCamera("tele", PixelFormat::kMono8, 32, 32, 10), nullptr);
  for (int i = 0; i < 10; ++i) {
    const uint64_t seq = static_cast<uint64_t>(i < 5 ? i : i + 2);
    writer.Write(
        TestFrame(PixelFormat::kBGR8, 64, 48, wide, seq, 2'000'000'000LL + i * 40'000'000LL),
        i == 5 ? 2 : 0);
  }
  for (int i = 0; i < 5; ++i) {
    writer.Write(TestFrame(PixelFormat::kMono8, 32, 32, tele, 50 + static_cast<uint64_t>(i),
                           2'010'000'000LL + i * 100'000'000LL));
  }
  writer.Close();
}

CameraModel PinholeModel(int width, int height) {
  return CameraModel("LENSMODEL_PINHOLE", {100, 100, width / 2.0 - 0.5, height / 2.0 - 0.5}, width,
                     height, Rigid3());
}

TEST(ReplayCli, JsonReportsFramesGapsDropsSpanAndRatePerCamera) {
  ScratchDir dir;
  const std::string session = dir / "s";
  const CameraModel model = PinholeModel(64, 48);
  RecordKnownSession(session, &model);

  const auto r = RunSpritestation("replay " + session + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto j = JsonReport(r.output);
  ASSERT_TRUE(j.is_object()) << r.output;
  EXPECT_EQ(j["name"], "known");
  EXPECT_EQ(j["frames"], 15);
  EXPECT_EQ(j["errors"], 0);
  ASSERT_EQ(j["cameras"].size(), 2u);
  const auto& wide = j["cameras"][0];
  EXPECT_EQ(wide["name"], "wide");
  EXPECT_EQ(wide["pixel_format"], "bgr8");
  EXPECT_EQ(wide["codec"], "ffv1");
  EXPECT_EQ(wide["model"], session + "/wide.cameramodel");
  EXPECT_EQ(wide["frames"], 10);
  EXPECT_EQ(wide["frames_in_csv"], 10);
  EXPECT_EQ(wide["first_timestamp_ns"], 2'000'000'000LL);
  EXPECT_EQ(wide["last_timestamp_ns"], 2'360'000'000LL);
  EXPECT_NEAR(wide["span_s"].get<double>(), 0.36, 1e-12);
  EXPECT_NEAR(wide["fps"].get<double>(), 25.0, 1e-9);
  EXPECT_EQ(wide["sequence_gaps"], 2);
  EXPECT_EQ(wide["recorded_drops"], 2);
  EXPECT_EQ(wide["frames_unreadable"], 0);
  const auto& tele = j["cameras"][1];
  EXPECT_EQ(tele["name"], "tele");
  EXPECT_EQ(tele["model"], "");
  EXPECT_EQ(tele["frames"], 5);
  EXPECT_NEAR(tele["span_s"].get<double>(), 0.4, 1e-12);
  EXPECT_NEAR(tele["fps"].get<double>(), 10.0, 1e-9);
  EXPECT_EQ(tele["sequence_gaps"], 0);
  EXPECT_EQ(tele["recorded_drops"], 0);

  // The table names the same figures.
  const auto text = RunSpritestation("replay " + session);
  ASSERT_EQ(text.exit_code, 0) << text.output;
  EXPECT_TRUE(Contains(text.output, "total: 15 frames replayed")) << text.output;
  EXPECT_TRUE(Contains(text.output, "25.00")) << text.output;
}

TEST(ReplayCli, RealtimeAndLoopOptions) {
  ScratchDir dir;
  const std::string session = dir / "s";
  RecordKnownSession(session, nullptr);
  const auto r = RunSpritestation("replay " + session + " --realtime --loop 2 --json");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto j = JsonReport(r.output);
  ASSERT_TRUE(j.is_object()) << r.output;
  EXPECT_EQ(j["realtime"], true);
  EXPECT_EQ(j["frames"], 30);
  // Paced by device time: two passes of a 0.41 s session cannot finish sooner.
  EXPECT_GE(j["seconds"].get<double>(), 0.41 + 0.36);
  const auto bad = RunSpritestation("replay " + session + " --loop -1");
  EXPECT_EQ(bad.exit_code, 2) << bad.output;
}

TEST(ReplayCli, MissingCameraModelIsNamedAndTheFramesStillReplay) {
  ScratchDir dir;
  const std::string session = dir / "s";
  const CameraModel model = PinholeModel(64, 48);
  RecordKnownSession(session, &model);
  const std::string model_path = session + "/wide.cameramodel";
  std::filesystem::remove(model_path);

  ReplaySource source(session);
  EXPECT_EQ(source.cameras()[0].model_path,
            "");  // nobody downstream gets a path that does not load
  int frames = 0;
  while (source.Next()) ++frames;
  EXPECT_EQ(frames, 15);
  EXPECT_EQ(source.stats().errors, 1u);
  EXPECT_TRUE(Contains(source.stats().last_error, model_path)) << source.stats().last_error;

  const auto r = RunSpritestation("replay " + session + " --json");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  const auto j = JsonReport(r.output);
  ASSERT_TRUE(j.is_object()) << r.output;
  EXPECT_EQ(j["frames"], 15);  // the report comes first, then the error
  EXPECT_TRUE(Contains(r.output, "spritestation: error: " + model_path)) << r.output;
  EXPECT_TRUE(std::filesystem::exists(session + "/wide.mkv"));  // replay changes nothing
}

TEST(ReplayCli, BrokenOrMismatchedCameraModelIsNamed) {
  ScratchDir dir;
  const std::string session = dir / "s";
  const CameraModel model = PinholeModel(64, 48);
  RecordKnownSession(session, &model);
  const std::string model_path = session + "/wide.cameramodel";
  std::ofstream(model_path, std::ios::trunc)
      << "{ 'lensmodel': 'LENSMODEL_PINHOLE', 'intrinsics': [1, 2";
  auto r = RunSpritestation("replay " + session);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_TRUE(Contains(r.output, model_path)) << r.output;

  PinholeModel(640, 480).Write(model_path);  // a model of another camera
  ReplaySource source(session);
  EXPECT_EQ(source.stats().errors, 1u);
  EXPECT_TRUE(Contains(source.stats().last_error,
                       model_path + ": imager is 640x480, the camera records 64x48"))
      << source.stats().last_error;
}

TEST(ReplayCli, BadSessionsExitTwoNamingTheFile) {
  ScratchDir dir;
  auto r = RunSpritestation("replay " + (dir / "nowhere"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_TRUE(Contains(r.output, dir / "nowhere")) << r.output;

  const std::string session = dir / "s";
  RecordKnownSession(session, nullptr);
  // A session.json with a wrong field type.
  std::string text;
  {
    std::ifstream in(session + "/session.json");
    text.assign(std::istreambuf_iterator<char>(in), {});
  }
  const std::string broken = dir / "broken";
  std::filesystem::copy(session, broken);
  const std::string fps = "\"fps\": 25.0";
  const size_t at = text.find(fps);
  ASSERT_NE(at, std::string::npos) << text;
  std::string bad = text;
  bad.replace(at, fps.size(), "\"fps\": \"fast\"");
  std::ofstream(broken + "/session.json", std::ios::trunc) << bad;
  r = RunSpritestation("replay " + broken);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_TRUE(Contains(
      r.output, broken + "/session.json: field 'cameras[0].fps': expected a positive number"))
      << r.output;

  // A CSV cut in the middle of a row is read up to its last whole row, and the cut is reported.
  const std::string cut = dir / "cut";
  std::filesystem::copy(session, cut);
  const std::string csv = cut + "/tele.frames.csv";
  std::filesystem::resize_file(csv, std::filesystem::file_size(csv) - 5);
  r = RunSpritestation("replay " + cut + " --json");
  EXPECT_EQ(r.exit_code, 2)
      << r.output;  // the recording was closed with 5 frames: the CSV lost one
  EXPECT_TRUE(Contains(r.output, csv + ": lists 4 frames, but the recording was closed with 5"))
      << r.output;
  const auto j = JsonReport(r.output);
  ASSERT_TRUE(j.is_object()) << r.output;
  EXPECT_EQ(j["cameras"][1]["frames"], 4);
  EXPECT_EQ(j["cameras"][1]["frames_without_row"], 1);
}

TEST(ReplayCli, TruncatedVideoExitsTwoNamingTheFile) {
  ScratchDir dir;
  const std::string session = dir / "s";
  const std::string video = RecordTruncatedSession(session);
  const auto cli = RunSpritestation("replay " + session);
  EXPECT_EQ(cli.exit_code, 2) << cli.output;
  EXPECT_TRUE(Contains(cli.output, video)) << cli.output;
}

TEST(ReplayCli, GarbageCsvExitsTwoNamingTheLine) {
  ScratchDir dir;
  const std::string session = dir / "s";
  const std::string csv = RecordSessionWithGarbageCsv(session);
  const auto cli = RunSpritestation("replay " + session);
  EXPECT_EQ(cli.exit_code, 2) << cli.output;
  EXPECT_TRUE(Contains(cli.output, csv + ":3")) << cli.output;
}

}  // namespace
}  // namespace ss
