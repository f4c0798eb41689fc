// Past one machine (issue 21): three daemons replaying three recorded sessions and two
// `transitions worker` processes, all at once on one PostgreSQL bank. The bank then holds
// exactly what `ingest` stores of each session (every sprite's fields and pixels), at one
// billboard scale, and the transition table equals a single-process build of the same bank.
#include <signal.h>

#include <chrono>
#include <fstream>
#include <map>
#include <memory>
#include <set>
#include <thread>
#include <vector>

// Eigen before httplib: <resolv.h> (through httplib) defines _res, a name Eigen uses.
#include <Eigen/Core>

#include <gtest/gtest.h>
#include <httplib.h>
#include <spdlog/fmt/fmt.h>

#include <nlohmann/json.hpp>

#include "core/bank.h"
#include "tests/e2e/daemon/station_fixture.h"
#include "tests/support/postgres_server.h"
#include "tests/support/test_support.h"

namespace ss {
namespace {

using testing::BackgroundCommand;
using testing::JsonInOutput;
using testing::PostgresServer;
using testing::PrivateNetworkError;
using testing::QueryInt;
using testing::RunSpritestation;
using testing::ScratchDir;
using Clock = std::chrono::steady_clock;

constexpr int kStations = 3;

uint64_t Fnv1a(const cv::Mat& m, uint64_t h) {
  if (m.empty()) return h;
  const cv::Mat c = m.isContinuous() ? m : m.clone();
  const auto* p = c.ptr<unsigned char>();
  for (size_t k = 0; k < c.total() * c.elemSize(); ++k) h = (h ^ p[k]) * 1099511628211ull;
  return h;
}

// Every stored sprite of each session (by the session's name, or "" for a bank of one session),
// as one line of its content: camera, clip, frame, every field to the last bit, its pixels'
// hash. Ids are left out (they differ between banks); mirrors point at their original's frame.
std::map<std::string, std::multiset<std::string>> SpritesBySession(const std::string& bank_path,
                                                                   bool by_name) {
  Bank bank(bank_path);
  std::map<int64_t, std::string> session_name;
  for (const SessionRecord& s : bank.ListSessions()) session_name[s.id] = by_name ? s.name : "";
  std::map<int64_t, CameraRecord> cameras;
  for (const CameraRecord& c : bank.ListCameras()) cameras[c.id] = c;
  std::map<int64_t, ClipRecord> clips;
  for (const ClipRecord& c : bank.ListClips()) clips[c.id] = c;
  const std::vector<SpriteFeatures> features = bank.LoadFeatures();  // originals and mirrors
  std::map<int64_t, int64_t> frame_of;
  for (const SpriteFeatures& f : features) frame_of[f.id] = f.frame;
  std::map<std::string, std::multiset<std::string>> out;
  for (const SpriteFeatures& f : features) {
    const SpriteRecord s = bank.LoadSprite(f.id);
    const ClipRecord& clip = clips.at(s.clip_id);
    const CameraRecord& camera = cameras.at(clip.camera_id);
    uint64_t h = 1469598103934665603ull;
    if (!s.mirrored) {
      const SpritePixels px = bank.LoadPixels(s.id);
      h = Fnv1a(px.shadow, Fnv1a(px.bgra, h));
    }
    std::string tags;
    for (const std::string& t : s.tags) tags += t + ",";
    out[session_name.at(camera.session_id)].insert(fmt::format(
        "{} track {} frames {}-{} | frame {} t {} mirror {} of {} | ground {:a} {:a} v {:a} {:a} "
        "rgb {:a} {:a} {:a} "
        "area {:a} ecc {:a} | box {} {} {} {} billboard {}x{} {:a} px/m anchor {:a} {:a} | tags {} "
        "| pixels {:x}",
        camera.name, clip.track_id, clip.first_frame, clip.last_frame, s.frame, s.timestamp_ns,
        s.mirrored, s.mirrored ? frame_of.at(s.mirror_of) : -1, s.ground_x_m, s.ground_y_m,
        s.velocity_x_m_s, s.velocity_y_m_s, s.mean_r, s.mean_g, s.mean_b, s.area_px, s.eccentricity,
        s.bbox_in_image.x, s.bbox_in_image.y, s.bbox_in_image.width, s.bbox_in_image.height,
        s.billboard_width_px, s.billboard_height_px, s.px_per_m, s.anchor_x_px, s.anchor_y_px, tags,
        h));
  }
  return out;
}

nlohmann::json Status(int port) {
  httplib::Client client("127.0.0.1", port);
  client.set_read_timeout(10, 0);
  const auto res = client.Get("/api/status");
  if (!res || res->status != 200) return {};
  return nlohmann::json::parse(res->body, nullptr, false);
}

// Every camera has replayed its whole recording and put every frame through the pipeline.
bool AllReplayed(const nlohmann::json& status) {
  if (status.is_null() || status["cameras"].empty()) return false;
  for (const auto& c : status["cameras"]) {
    if (c["state"] != "finished" || c["queue_depth"] != 0 ||
        c["frames_processed"] != c["frames_captured"]) {
      return false;
    }
  }
  return true;
}

TEST(ScaleOut, ThreeDaemonsAndTwoWorkersStoreWhatIngestStores) {
  ASSERT_EQ(PrivateNetworkError(), "");
  PostgresServer server;
  ASSERT_TRUE(server.ok());
  ScratchDir dir;
  // Three sessions whose cameras stand in different places (the seed places them): alone, their
  // stations would choose 260, 240 and 260 px/m. The bank must keep one scale. (Seed 42's
  // animal spends its 5 s at the walls since the subjects explore the floor: 5 sprites.)
  constexpr int kSeeds[] = {41, 43, 44};
  for (int k = 0; k < kStations; ++k) {
    const auto synth =
        RunSpritestation(fmt::format("synth --out {} --kind animal --seconds 5 --fps 30 --size "
                                     "480x360 --cameras 2 --subjects 1 --seed {}",
                                     dir / ("session-" + std::to_string(k)), kSeeds[k]));
    ASSERT_EQ(synth.exit_code, 0) << synth.output;
  }
  const std::string pg = server.CreateDatabase("studio");

  // Two workers wait for work; then three stations replay their sessions at once, as fast as
  // they run (a replay that is not paced holds its frames back instead of dropping them).
  std::vector<std::unique_ptr<BackgroundCommand>> workers;
  for (const char* name : {"a", "b"}) {
    workers.push_back(std::make_unique<BackgroundCommand>(
        fmt::format("--log-level warn transitions worker --bank {} --name {} --json", pg, name),
        dir / (std::string("worker-") + name + ".log")));
  }
  std::vector<std::unique_ptr<BackgroundCommand>> daemons;
  for (int k = 0; k < kStations; ++k) {
    const std::string session = dir / ("session-" + std::to_string(k));
    const std::string config = dir / ("station-" + std::to_string(k) + ".yaml");
    std::ofstream(config) << "version: 1\ncameras:\n"
                          << "  - name: cam0\n    source: replay\n    session: " << session
                          << "\n    realtime: false\n"
                          << "  - name: cam1\n    source: replay\n    session: " << session
                          << "\n    realtime: false\n"
                          << "storage:\n  bank: " << pg
                          << "\n  spool_dir: " << (dir / ("spool-" + std::to_string(k)))
                          << "\ncontrol:\n  port: 0\n";
    daemons.push_back(std::make_unique<BackgroundCommand>(
        fmt::format("daemon --config {} --session take-{} --json", config, k),
        dir / ("daemon-" + std::to_string(k) + ".log")));
  }
  std::vector<int> ports;
  for (auto& d : daemons) {
    ASSERT_TRUE(d->WaitForOutput("daemon: control API on", 60)) << d->output();
    const std::string out = d->output();
    ports.push_back(std::stoi(out.substr(out.find("(port ") + 6)));
  }
  // Each daemon stops (SIGTERM: its session's last clips stored) once its recording is through.
  for (int k = 0; k < kStations; ++k) {
    nlohmann::json status;
    const auto deadline = Clock::now() + std::chrono::seconds(240);
    while (Clock::now() < deadline && !AllReplayed(status = Status(ports[k]))) {
      std::this_thread::sleep_for(std::chrono::milliseconds(200));
    }
    ASSERT_TRUE(AllReplayed(status)) << status.dump(2);
    for (const auto& c : status["cameras"]) {
      EXPECT_EQ(c["dropped"]["total"], 0) << c.dump(2);
      EXPECT_EQ(c["frames_while_learning"], 0) << c.dump(2);
    }
    daemons[k]->Signal(SIGTERM);
    ASSERT_EQ(daemons[k]->Wait(60), 0) << daemons[k]->output();
    const nlohmann::json final_status = JsonInOutput(daemons[k]->output());
    EXPECT_EQ(final_status["bank"]["batches_failed"], 0) << final_status.dump(2);
    EXPECT_GT(final_status["bank"]["sprites_stored"].get<int64_t>(), 0) << final_status.dump(2);
  }
  // The workers (and the stations' own share, done before they stopped) finish every unit.
  const int64_t clips = QueryInt(pg, "SELECT count(*) FROM clips WHERE complete = 1");
  ASSERT_GE(clips, 2 * kStations);
  const auto deadline = Clock::now() + std::chrono::seconds(240);
  while (Clock::now() < deadline &&
         QueryInt(pg, "SELECT count(*) FROM transition_work WHERE done = 1") < clips) {
    std::this_thread::sleep_for(std::chrono::milliseconds(250));
  }
  EXPECT_EQ(QueryInt(pg, "SELECT count(*) FROM transition_work WHERE done = 1"), clips);
  int64_t worker_units = 0;
  for (auto& w : workers) {
    w->Signal(SIGTERM);  // finishes its unit, prints its summary
    ASSERT_EQ(w->Wait(60), 0) << w->output();
    worker_units += JsonInOutput(w->output())["units"].get<int64_t>();
  }
  std::printf("%lld complete clips: %lld units done by the two workers, the rest by the stations\n",
              static_cast<long long>(clips), static_cast<long long>(worker_units));

  // One scale for the whole bank, whichever station recorded it first.
  const std::vector<double> scales = Bank(pg).BillboardScales();
  ASSERT_EQ(scales.size(), 1u);
  const std::string ingest_config = dir / "ingest.yaml";
  std::ofstream(ingest_config) << "version: 1\npipeline:\n  px_per_m: "
                               << fmt::format("{:.17g}", scales[0]) << "\n";

  // The bank holds exactly the union of what ingest stores of each session.
  const auto shared = SpritesBySession(pg, /*by_name=*/true);
  size_t total = 0;
  for (int k = 0; k < kStations; ++k) {
    const std::string bank = dir / ("ingest-" + std::to_string(k) + ".db");
    const auto ingest = RunSpritestation(
        fmt::format("--log-level warn ingest {} --bank {} --config {} --no-transitions",
                    dir / ("session-" + std::to_string(k)), bank, ingest_config));
    ASSERT_EQ(ingest.exit_code, 0) << ingest.output;
    const auto want = SpritesBySession(bank, /*by_name=*/false);
    ASSERT_EQ(want.size(), 1u);
    const std::string name = "take-" + std::to_string(k);
    ASSERT_TRUE(shared.count(name)) << name;
    const std::multiset<std::string>& got = shared.at(name);
    const std::multiset<std::string>& expected = want.begin()->second;
    EXPECT_GT(expected.size(), 50u) << name;
    EXPECT_EQ(got.size(), expected.size()) << name;
    std::vector<std::string> missing, extra;
    std::set_difference(expected.begin(), expected.end(), got.begin(), got.end(),
                        std::back_inserter(missing));
    std::set_difference(got.begin(), got.end(), expected.begin(), expected.end(),
                        std::back_inserter(extra));
    EXPECT_TRUE(missing.empty() && extra.empty())
        << name << ": " << missing.size() << " sprites of ingest missing, " << extra.size()
        << " not ingest's\n"
        << (missing.empty() ? "" : "missing: " + missing.front() + "\n")
        << (extra.empty() ? "" : "extra: " + extra.front());
    total += got.size();
  }
  EXPECT_EQ(shared.size(), static_cast<size_t>(kStations));
  EXPECT_EQ(static_cast<int64_t>(total), Bank(pg).Counts().sprites);

  // The transitions equal a single-process build of a copy of the same bank.
  const std::string single = dir / "single.db";
  ASSERT_EQ(RunSpritestation("--log-level warn bank copy " + pg + " " + single).exit_code, 0);
  const auto build = RunSpritestation("--log-level warn transitions " + single + " --json");
  ASSERT_EQ(build.exit_code, 0) << build.output;
  const auto got = Bank(pg).LoadTransitions();
  const auto want = Bank(single).LoadTransitions();
  ASSERT_GT(want.size(), 0u);
  ASSERT_EQ(got.size(), want.size());
  size_t differ = 0;
  for (size_t k = 0; k < want.size(); ++k) {
    if (got[k].from_sprite != want[k].from_sprite || got[k].to_sprite != want[k].to_sprite ||
        got[k].d != want[k].d || got[k].cost != want[k].cost) {
      ++differ;
    }
  }
  EXPECT_EQ(differ, 0u) << "of " << want.size();
}

}  // namespace
}  // namespace ss
