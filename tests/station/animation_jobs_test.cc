// The animation jobs' controller (station/animation_jobs.h) on the scene tests' walker bank: a
// spec is optimized, judged, rendered and saved in a folder of its own; a second job waits its
// turn; a cancel ends a job within a second; files outside the station's folders and budgets
// over its cap are refused before anything is made; a job cut off by a stop reads as failed.
#include "station/animation_jobs.h"

#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <thread>

#include "animate/sequence_io.h"
#include "capture/recording/video_file.h"
#include "core/error.h"
#include "core/error_kinds.h"
#include "tests/animate/scene_fixture.h"

namespace ss {
namespace {

namespace fs = std::filesystem;

std::string Spec(double budget_s, const std::string& bank = "walker.ssbank") {
  return "version: 1\nframe_rate: 30\ncamera: virtual.cameramodel\nbackground: floor.png\n"
         "banks: [" +
         bank + "]\nlength: {min_frames: 40, max_frames: 90}\noptimizer: {time_budget_s: " +
         std::to_string(budget_s) +
         "}\nsprites:\n  - name: walker\n    start: [0, 0]\n    constraints:\n"
         "      - path: {points: [[0, 0], [0.5, 0], [0.5, 0.4]]}\n";
}

class AnimationJobsTest : public testing::SceneTest {
 protected:
  AnimationJobsOptions Options() const {
    AnimationJobsOptions options;
    options.folder = dir_ / "animations";
    options.base_dir = dir_.path().string();
    options.roots = {dir_.path().string()};
    return options;
  }
  // Waits until the job's state is one of `states`; its JSON (fails after `seconds`).
  static nlohmann::json WaitFor(const AnimationJobs& jobs, int64_t id,
                                const std::vector<std::string>& states, double seconds) {
    const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    nlohmann::json j;
    while (std::chrono::steady_clock::now() < until) {
      j = jobs.Job(id);
      if (std::find(states.begin(), states.end(), j["state"]) != states.end()) return j;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    ADD_FAILURE() << "job " << id << " still " << j["state"] << " after " << seconds << " s";
    return j;
  }
};

TEST_F(AnimationJobsTest, AJobIsOptimizedJudgedRenderedAndSaved) {
  AnimationJobs jobs(Options());
  EXPECT_TRUE(jobs.Brief().is_null());
  const int64_t id = jobs.Submit(Spec(1.0));
  EXPECT_EQ(id, 1);
  const nlohmann::json j = WaitFor(jobs, id, {"done", "failed"}, 120);
  ASSERT_EQ(j["state"], "done") << j.dump(2);
  const fs::path folder = dir_.path() / "animations" / "0001";
  // The sequences as `animate` writes them, and the judge's figures in them.
  const SequenceFile file = ReadSequenceFile((folder / "sequences.json").string());
  EXPECT_EQ(file.num_steps, j["num_steps"]);
  EXPECT_GE(file.num_steps, 40);
  std::ifstream in(folder / "sequences.json");
  EXPECT_EQ(nlohmann::json::parse(in), j["sequences"]);
  ASSERT_TRUE(j["judge"].contains("paths")) << j["judge"].dump();
  EXPECT_EQ(j["judge"]["paths"][0]["sprite"], "walker");
  EXPECT_FALSE(j["progress"]["trace"].empty());
  EXPECT_GT(j["progress"]["turns"].get<int>(), 0);
  // the cost by kind of term over time: the path's and the length's
  ASSERT_FALSE(j["progress"]["by_kind"].empty());
  EXPECT_TRUE(j["progress"]["by_kind"].back()[1].contains("path")) << j["progress"]["by_kind"];
  ASSERT_EQ(j["tracks"].size(), 1U);
  EXPECT_EQ(j["tracks"][0]["positions"].size(), static_cast<size_t>(file.num_steps));
  // The render: a video of every step, and one JPEG a step for the page.
  EXPECT_EQ(static_cast<int>(ReadVideoFrames((folder / "render.mp4").string()).size()),
            file.num_steps);
  EXPECT_NO_THROW(jobs.Frame(id, file.num_steps - 1));
  EXPECT_THROW(jobs.Frame(id, file.num_steps), NotFoundError);
  EXPECT_EQ(jobs.File(id, "spec.yaml"), (folder / "spec.yaml").string());
  EXPECT_THROW(jobs.File(id, "../station.yaml"), NotFoundError);
  const nlohmann::json list = jobs.List();
  ASSERT_EQ(list["jobs"].size(), 1U);
  EXPECT_EQ(list["jobs"][0]["files"]["render"], "/api/animations/1/files/render.mp4");
  EXPECT_EQ(jobs.Brief()["state"], "done");
}

TEST_F(AnimationJobsTest, OneJobAtATimeAndACancelEndsItWithinASecond) {
  AnimationJobs jobs(Options());
  const int64_t first = jobs.Submit(Spec(300));
  WaitFor(jobs, first, {"running"}, 30);
  EXPECT_THROW(jobs.Submit(Spec(1)), ConflictError);
  // Cancelled while it optimizes (the bank's load and the F/B sets are not cut short): once the
  // optimizer has kept a move.
  for (int i = 0; i < 3000 && jobs.Job(first)["progress"]["trace"].empty(); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ASSERT_FALSE(jobs.Job(first)["progress"]["trace"].empty()) << "no move kept in 30 s";
  const auto asked = std::chrono::steady_clock::now();
  jobs.Cancel(first);
  const nlohmann::json j = WaitFor(jobs, first, {"cancelled", "done", "failed"}, 5);
  EXPECT_EQ(j["state"], "cancelled");
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - asked).count(), 1.0);
  EXPECT_TRUE(j["files"]["sequences"].is_null());
  // The next job gets a folder of its own: the refused one made none.
  EXPECT_EQ(jobs.Submit(Spec(0.5)), 2);
  EXPECT_EQ(WaitFor(jobs, 2, {"done", "failed"}, 120)["state"], "done");
}

TEST_F(AnimationJobsTest, OutsideFilesAndBudgetsOverTheCapAreRefusedBeforeAnythingIsMade) {
  AnimationJobsOptions options = Options();
  options.max_time_budget_s = 60;
  AnimationJobs jobs(options);
  const testing::ScratchDir elsewhere;
  fs::copy_file(dir_ / "walker.ssbank", elsewhere / "walker.ssbank");
  auto error_of = [&](const std::string& spec) -> std::string {
    try {
      jobs.Submit(spec);
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_EQ(error_of(Spec(1, elsewhere / "walker.ssbank")),
            "spec:5: banks[0]: " + (elsewhere / "walker.ssbank") +
                ": outside the station's folders (" + dir_.path().string() + "); not opened");
  EXPECT_EQ(error_of(Spec(61)),
            "spec: optimizer.time_budget_s: at most 60 s on this station, got 61");
  EXPECT_EQ(error_of("version: 1\nframe_rate: fast\n").rfind("spec:2: frame_rate: ", 0), 0U);
  EXPECT_FALSE(fs::exists(dir_ / "animations/0001"));
  EXPECT_THROW(jobs.Job(1), NotFoundError);
}

// The F/B sets are weighed before they are made: a job over the station's budget fails
// saying what it would take, and the station takes the next job.
TEST_F(AnimationJobsTest, AJobWhoseSetsWouldExceedTheMemoryBudgetFailsSayingSo) {
  AnimationJobsOptions options = Options();
  options.max_set_bytes = 1000;
  AnimationJobs jobs(options);
  const int64_t id = jobs.Submit(Spec(1));
  const nlohmann::json j = WaitFor(jobs, id, {"done", "failed", "cancelled"}, 30);
  EXPECT_EQ(j["state"], "failed");
  EXPECT_EQ(j["error"].get<std::string>().rfind("memory: the optimizer's F/B sets would take ", 0),
            0U)
      << j["error"];
  EXPECT_EQ(jobs.Submit(Spec(1)), id + 1);
  jobs.Stop();
}

TEST_F(AnimationJobsTest, AJobCutOffByAStopReadsAsFailedAndItsNumberIsNotReused) {
  const fs::path folder = dir_.path() / "animations" / "0007";
  fs::create_directories(folder);
  std::ofstream(folder / "spec.yaml") << Spec(1);
  std::ofstream(folder / "job.json") << R"({"id": 7, "state": "running", "name": "walker"})";
  AnimationJobs jobs(Options());
  const nlohmann::json j = jobs.Job(7);
  EXPECT_EQ(j["state"], "failed");
  EXPECT_EQ(j["error"], "the station stopped while it ran");
  EXPECT_EQ(jobs.Submit(Spec(0.5)), 8);
  jobs.Stop();  // cancels it and waits
  EXPECT_NE(jobs.Job(8)["state"], "running");
}

}  // namespace
}  // namespace ss
