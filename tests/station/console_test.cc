// The console's backend pieces without a server: merge patches, the event stream's
// "latest state only" rule, the preview's exposure figures and candidate outlines,
// the replay folders and config, and the bank view (sessions, clips, sprite detail,
// billboards, tags on a run of frames, CSV export).
#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <thread>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "capture/replay/replay_source.h"
#include "core/bank.h"
#include "core/error_kinds.h"
#include "core/session.h"
#include "station/console_bank.h"
#include "station/console_events.h"
#include "station/preview.h"
#include "station/station_host.h"
#include "tests/support/test_support.h"

namespace ss {
namespace {

using ss::testing::ScratchDir;

// Splits an event stream's text into (event name, data) pairs, checking the ids count up.
std::vector<std::pair<std::string, nlohmann::json>> ParseEvents(const std::string& text,
                                                                uint64_t* next_id) {
  std::vector<std::pair<std::string, nlohmann::json>> out;
  size_t at = 0;
  while (at < text.size()) {
    const size_t end = text.find("\n\n", at);
    EXPECT_NE(end, std::string::npos) << text;
    if (end == std::string::npos) break;
    std::istringstream block(text.substr(at, end - at));
    std::string line, name;
    nlohmann::json data;
    while (std::getline(block, line)) {
      if (line.rfind("id: ", 0) == 0) {
        EXPECT_EQ(std::stoull(line.substr(4)), (*next_id)++);
      }
      if (line.rfind("event: ", 0) == 0) name = line.substr(7);
      if (line.rfind("data: ", 0) == 0) data = nlohmann::json::parse(line.substr(6));
    }
    out.emplace_back(name, data);
    at = end + 2;
  }
  return out;
}

TEST(Console, MergePatchTurnsOneStateIntoTheOther) {
  const nlohmann::json a = {{"state", "running"},
                            {"session", {{"active", false}, {"name", ""}}},
                            {"cameras", {{{"name", "cam0"}, {"fps", 30.0}}}},
                            {"gone", 1}};
  const nlohmann::json b = {
      {"state", "running"},
      {"session", {{"active", true}, {"name", "take 1"}}},
      {"cameras", {{{"name", "cam0"}, {"fps", 29.5}}, {{"name", "cam1"}, {"fps", 30.0}}}},
      {"new", {{"x", 2}}}};
  const nlohmann::json patch = MergePatch(a, b);
  EXPECT_FALSE(patch.contains("state"));  // unchanged members are not sent
  EXPECT_TRUE(patch["gone"].is_null());
  EXPECT_EQ(patch["session"], (nlohmann::json{{"active", true}, {"name", "take 1"}}));
  nlohmann::json applied = a;
  applied.merge_patch(patch);  // RFC 7386, as the page applies it
  EXPECT_EQ(applied, b);
  EXPECT_TRUE(MergePatch(b, b).empty());
}

TEST(Console, ASlowReaderGetsOnlyTheLatestState) {
  std::atomic<int> counter{0};
  ConsoleEvents events([&] { return nlohmann::json{{"n", counter.load()}, {"fixed", "x"}}; }, 0.01);
  events.Start();
  ConsoleEvents::Stream stream(events);
  uint64_t next_id = 1;
  auto first = ParseEvents(stream.Next(), &next_id);
  ASSERT_EQ(first.size(), 1u);
  EXPECT_EQ(first[0].first, "snapshot");
  nlohmann::json held = first[0].second["status"];
  EXPECT_EQ(events.connections(), 1u);
  // The state changes 20 times while the reader reads nothing.
  for (int k = 1; k <= 20; ++k) {
    counter = k;
    events.Changed();
    std::this_thread::sleep_for(std::chrono::milliseconds(15));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  const auto next = ParseEvents(stream.Next(), &next_id);
  int patches = 0;
  for (const auto& [name, data] : next) {
    if (name != "patch") continue;
    ++patches;
    held.merge_patch(data);
  }
  EXPECT_EQ(patches, 1) << "one patch to the latest state, not one per change";
  EXPECT_EQ(held, (nlohmann::json{{"n", 20}, {"fixed", "x"}}));
  events.Stop();
  EXPECT_EQ(stream.Next(), "") << "a stopping hub ends every stream";
}

TEST(Console, AToldChangeIsSentAtOnceAndAnIdleStatusIsReadOnlyToSample) {
  std::atomic<int> counter{0};
  // Figures sampled every 2 s: what comes sooner came because it was told.
  ConsoleEvents events([&] { return nlohmann::json{{"n", counter.load()}}; }, 0.01, 2.0);
  events.Start();
  ConsoleEvents::Stream stream(events);
  uint64_t next_id = 1;
  nlohmann::json held = ParseEvents(stream.Next(), &next_id).at(0).second["status"];
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  EXPECT_EQ(events.reads(), 1u) << "the status was read again with nothing told";

  counter = 1;
  events.Changed();
  const auto told = std::chrono::steady_clock::now();
  while (held["n"] != 1) {
    for (const auto& [name, data] : ParseEvents(stream.Next(), &next_id)) {
      if (name == "patch") held.merge_patch(data);
    }
  }
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - told).count(), 1.0)
      << "a told change waited for the sample";
  EXPECT_EQ(events.reads(), 2u);

  // Untold, a change still comes with the next sample.
  counter = 2;
  while (held["n"] != 2) {
    for (const auto& [name, data] : ParseEvents(stream.Next(), &next_id)) {
      if (name == "patch") held.merge_patch(data);
    }
  }
  EXPECT_GE(std::chrono::duration<double>(std::chrono::steady_clock::now() - told).count(), 1.0);
  events.Stop();
}

TEST(Console, ExposureFiguresMeasureTheGreenScreen) {
  PreviewFrame frame;
  frame.bgr = cv::Mat(200, 400, CV_8UC3, cv::Scalar(128, 128, 128));
  // The left half an evenly lit green screen, the right half grey; ten white (clipped) rows.
  frame.bgr(cv::Rect(0, 0, 200, 200)).setTo(cv::Scalar(40, 180, 50));
  frame.bgr(cv::Rect(200, 0, 200, 10)).setTo(cv::Scalar(255, 255, 255));
  ExposureFigures even = MeasureExposure(frame);
  ASSERT_TRUE(even.measured);
  EXPECT_NEAR(even.green_fraction, 0.5, 0.01);
  EXPECT_NEAR(even.clipped_percent, 100.0 * 200 * 10 / (400 * 200), 0.5);
  EXPECT_NEAR(even.green_uniformity, 1.0, 1e-9);
  EXPECT_NEAR(even.green_min_max, 1.0, 1e-9);
  EXPECT_EQ(even.histogram_g[180 * 32 / 256],
            static_cast<uint32_t>(100 * 100));  // every 2nd pixel and row
  // Now lit from one side: green falls from 220 to 60 across the screen.
  for (int x = 0; x < 200; ++x) {
    const int g = 220 - x * 160 / 200;
    frame.bgr(cv::Rect(x, 0, 1, 200)).setTo(cv::Scalar(20, g, 20));
  }
  const ExposureFigures uneven = MeasureExposure(frame);
  EXPECT_LT(uneven.green_uniformity, 0.8);
  EXPECT_LT(uneven.green_min_max, 0.5);
  // Under a matte the subject is not green screen, however green it is.
  frame.alpha = cv::Mat(200, 400, CV_8U, cv::Scalar(0));
  frame.alpha(cv::Rect(0, 0, 100, 200)).setTo(255);
  EXPECT_NEAR(MeasureExposure(frame).green_fraction, 0.25, 0.01);
}

TEST(Console, CandidateOutlinesFollowTheSilhouette) {
  Candidate c;
  c.bbox = cv::Rect(300, 100, 80, 80);
  c.alpha = cv::Mat(80, 80, CV_8U, cv::Scalar(0));
  cv::circle(c.alpha, cv::Point(40, 40), 30, cv::Scalar(255), cv::FILLED);
  c.contact_point = cv::Point2d(340, 170);
  CandidateVerdict v{&c, 7, Eigen::Vector2d(0.1, 0.2), Discard::kTouchesWall};
  const std::vector<PreviewCandidate> out = PreviewCandidates({v});
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].track, 7);
  EXPECT_NEAR(cv::contourArea(out[0].outline), 3.14159 * 30 * 30, 0.06 * 3.14159 * 30 * 30);
  const cv::Rect box = cv::boundingRect(out[0].outline);
  EXPECT_NEAR(box.x, 310, 1);  // in camera pixels: the crop's offset added
  EXPECT_NEAR(box.y, 110, 1);
  PreviewFrame frame;
  frame.bgr = cv::Mat(480, 640, CV_8UC3, cv::Scalar(0, 0, 0));
  frame.candidates = out;
  const nlohmann::json j = SpritesViewJson(frame, true, "data:x", 1.0);
  EXPECT_EQ(j["candidates"][0]["verdict"], "touches_wall");
  EXPECT_EQ(j["candidates"][0]["ground"][1], 0.2);
}

TEST(Console, PreviewViewsAreScaledAndKeyed) {
  PreviewFrame frame;
  frame.bgr = cv::Mat(480, 640, CV_8UC3, cv::Scalar(0, 200, 0));
  frame.bgr(cv::Rect(100, 100, 50, 50)).setTo(cv::Scalar(0, 0, 255));
  cv::Mat raw = RenderPreview(frame, PreviewView::kRaw, 320);
  EXPECT_EQ(raw.size(), cv::Size(320, 240));
  // Keyed before the keyer learnt: the frame dimmed.
  cv::Mat dimmed = RenderPreview(frame, PreviewView::kKeyed, 640);
  EXPECT_LT(dimmed.at<cv::Vec3b>(10, 10)[1], 100);
  frame.alpha = cv::Mat(480, 640, CV_8U, cv::Scalar(0));
  frame.alpha(cv::Rect(100, 100, 50, 50)).setTo(255);
  frame.shadow = cv::Mat(480, 640, CV_8U, cv::Scalar(0));
  cv::Mat keyed = RenderPreview(frame, PreviewView::kKeyed, 640);
  EXPECT_EQ(keyed.at<cv::Vec3b>(10, 10), cv::Vec3b(128, 128, 128));  // background: grey
  EXPECT_EQ(keyed.at<cv::Vec3b>(120, 120), cv::Vec3b(0, 0, 255));    // the subject as it is
  const std::vector<uint8_t> jpeg = EncodeJpeg(keyed);
  EXPECT_EQ(cv::imdecode(jpeg, cv::IMREAD_COLOR).size(), keyed.size());
  EXPECT_EQ(Base64({'M', 'a', 'n'}), "TWFu");
  EXPECT_EQ(Base64({'M', 'a'}), "TWE=");
  EXPECT_EQ(Base64({'M'}), "TQ==");
}

TEST(Console, ReplayFoldersListSessionsAndMakeAReplayConfig) {
  ScratchDir dir;
  SessionInfo info;
  info.name = "walk";
  info.created = "2026-12-01T10:00:00Z";
  SessionCamera cam;
  cam.name = "cam0";
  cam.video = "cam0.mkv";
  cam.frames_csv = "cam0.frames.csv";
  cam.width = 640;
  cam.height = 480;
  cam.fps = 30;
  cam.frames = 150;
  info.cameras = {cam, cam};
  info.cameras[1].name = "cam1";
  info.cameras[1].video = "cam1.mkv";
  info.cameras[1].frames_csv = "cam1.frames.csv";
  std::filesystem::create_directories(dir.path() / "a" / "walk");
  WriteSessionInfo(dir / "a/walk", info);
  std::filesystem::create_directories(dir.path() / "broken");
  std::ofstream(dir / "broken/session.json") << "{not json";
  const auto sessions =
      FindRecordedSessions({dir.path().string(), (dir.path() / "missing").string()});
  ASSERT_EQ(sessions.size(), 2u);
  EXPECT_EQ(sessions[0].path, (dir.path() / "a" / "walk").string());
  EXPECT_EQ(sessions[0].info.cameras.size(), 2u);
  EXPECT_DOUBLE_EQ(sessions[0].seconds, 5.0);
  EXPECT_TRUE(sessions[0].error.empty()) << sessions[0].error;
  EXPECT_NE(sessions[1].error.find("session.json"), std::string::npos) << sessions[1].error;

  StationConfig live;
  live.cameras.resize(1);
  live.cameras[0].name = "studio";
  live.cameras[0].source = "aravis";
  live.enclosure.floor = GroundPolygon({{0, 0}, {1, 0}, {1, 1}});
  live.storage.bank = "/tmp/x.bank";
  const StationConfig replay = ReplayStationConfig(live, info, sessions[0].path, false, true);
  ASSERT_EQ(replay.cameras.size(), 2u);
  EXPECT_EQ(replay.cameras[1].source, "replay");
  EXPECT_EQ(replay.cameras[1].backend.Get<ReplayCameraKeys>(),
            (ReplayCameraKeys{sessions[0].path, "cam1", true, false}));
  EXPECT_EQ(replay.storage.bank, live.storage.bank);
  EXPECT_FALSE(replay.enclosure.floor.empty()) << "no floor in the session: the config's is kept";
}

SpriteRecord Sprite(int64_t frame, bool mirrored) {
  SpriteRecord s;
  s.frame = frame;
  s.timestamp_ns = 1'000'000'000 + frame * 33'333'333;
  s.mirrored = mirrored;
  s.ground_x_m = 0.1 * frame;
  s.velocity_x_m_s = mirrored ? -0.3 : 0.3;
  s.area_px = 400;
  s.px_per_m = 200;
  s.billboard_width_px = 20;
  s.billboard_height_px = 40;
  s.anchor_x_px = 10;
  s.anchor_y_px = 39;
  if (!mirrored) {
    s.pixels.bgra = cv::Mat(40, 20, CV_8UC4, cv::Scalar(10, 20, 30, 255));
    s.pixels.shadow = cv::Mat(40, 20, CV_8U, cv::Scalar(0));
  }
  return s;
}

TEST(Console, TheBankViewShowsClipsSpritesAndTagsARunOfFrames) {
  ScratchDir dir;
  const std::string path = dir / "bank.sqlite";
  int64_t clip_id = 0;
  std::vector<int64_t> ids;
  {
    BankWriter w(path);
    const int64_t session =
        w.AddSession({0, "take-1@x", "take 1", "2026-12-01T10:00:00Z", "station"});
    const int64_t camera = w.AddCamera(session, {0, 0, "cam0", "", 640, 480});
    std::vector<SpriteRecord> batch;
    for (int64_t f = 10; f < 16; ++f) {
      batch.push_back(Sprite(f, false));
      batch.push_back(Sprite(f, true));
    }
    ClipRecord clip;
    clip.camera_id = camera;
    clip.track_id = 3;
    clip.first_frame = 10;
    clip.last_frame = 15;
    clip.complete = true;
    const AppendResult r = w.AppendClipBatch(clip, batch);
    clip_id = r.clip_id;
    ids = r.sprite_ids;
    w.UpsertTransitions({{ids[0], ids[4], 1.5, 2.5}, {ids[2], ids[0], 0.5, 0.75}});
  }
  const ConsoleBank bank(path);
  const nlohmann::json sessions = bank.Sessions();
  ASSERT_EQ(sessions.size(), 1u);
  EXPECT_EQ(sessions[0]["name"], "take 1");
  EXPECT_EQ(sessions[0]["clips"], 1);
  EXPECT_EQ(sessions[0]["sprites"], 6) << "originals only";
  const nlohmann::json clips = bank.Clips(sessions[0]["id"]);
  ASSERT_EQ(clips.size(), 1u);
  EXPECT_EQ(clips[0]["camera"], "cam0");
  const nlohmann::json sprites = bank.ClipSprites(clip_id);
  ASSERT_EQ(sprites.size(), 6u);
  EXPECT_EQ(sprites[0]["frame"], 10);
  const nlohmann::json detail = bank.Sprite(ids[0]);
  EXPECT_EQ(detail["camera"], "cam0");
  EXPECT_EQ(detail["session"], "take 1");
  EXPECT_DOUBLE_EQ(detail["features"]["area_m2"].get<double>(), 400.0 / (200 * 200));
  ASSERT_EQ(detail["transitions_out"].size(), 1u);
  EXPECT_EQ(detail["transitions_out"][0]["sprite"], ids[4]);
  EXPECT_EQ(detail["transitions_in"][0]["sprite"], ids[2]);
  EXPECT_THROW(bank.Sprite(999999), NotFoundError);
  EXPECT_THROW(bank.Clips(42), NotFoundError);
  // The billboard as PNG with alpha, scaled down.
  const std::vector<uint8_t> png = bank.BillboardPng(ids[0], 20);
  const cv::Mat image = cv::imdecode(png, cv::IMREAD_UNCHANGED);
  EXPECT_EQ(image.size(), cv::Size(10, 20));
  EXPECT_EQ(image.channels(), 4);
  // Frames 11..13 tagged: their originals and mirrors.
  EXPECT_EQ(bank.Tag({{"tag", "stand"}, {"clip", clip_id}, {"first_frame", 11}, {"last_frame", 13}},
                     false),
            6);
  EXPECT_EQ(Bank(path).SpritesTagged("stand").size(), 6u);
  EXPECT_EQ(bank.Clips(sessions[0]["id"])[0]["tags"]["stand"], 3);
  EXPECT_THROW(bank.Tag({{"tag", "bad tag!"}, {"sprites", {ids[0]}}}, false), InputError);
  EXPECT_THROW(bank.Tag({{"tag", "x"}, {"sprite", {ids[0]}}}, false), InputError);
  EXPECT_THROW(bank.Tag({{"tag", "x"}, {"sprites", {999999}}}, false), InputError);
  const std::string csv = bank.ExportCsv(std::nullopt, "stand");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 7) << csv;  // header + 6
  EXPECT_EQ(bank.Tag({{"tag", "stand"}, {"sprites", {ids[2]}}}, true), 1);
  EXPECT_EQ(Bank(path).SpritesTagged("stand").size(), 5u);
}

}  // namespace
}  // namespace ss
