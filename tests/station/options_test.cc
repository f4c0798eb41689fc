// Each station component's options: the defaults are valid, a value out of range is refused
// naming its field, and the component refuses it with an InputError before it starts.
#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "core/error.h"
#include "station/camera_runner.h"
#include "station/console_labels.h"
#include "station/control_server.h"
#include "station/station.h"
#include "tests/support/error_text.h"
#include "tests/support/option_problems.h"

namespace ss {
namespace {

using testing::InputErrorOf;
using testing::Names;
using testing::Problems;

TEST(StationOptions, DefaultsAreValid) {
  EXPECT_EQ(Problems(StationOptions{}), "");
  EXPECT_EQ(Problems(CameraRunnerOptions{}), "");
  EXPECT_EQ(Problems(ControlServerOptions{}), "");
  EXPECT_EQ(Problems(ConsoleLabelsOptions{}), "");
}

TEST(StationOptions, Station) {
  StationOptions o;
  o.offline_after_s = 0;
  EXPECT_TRUE(Names(Problems(o), "offline_after_s"));
  o = {};
  o.weights = DefaultWeights();
  o.weights->feature_scale[0] = -1;
  EXPECT_TRUE(Names(Problems(o), "weights.feature_scale"));
  // Refused before the config is looked at (it has no camera either).
  o = {};
  o.offline_after_s = std::nan("");
  const std::string what = InputErrorOf([&] { Station station(o); });
  EXPECT_EQ(what.rfind("station options: offline_after_s: ", 0), 0u) << what;
}

TEST(StationOptions, CameraRunner) {
  CameraRunnerOptions o;
  o.backoff_min_s = 2;
  o.backoff_max_s = 1;
  o.preview_interval_s = -1;
  o.pipeline.queue_frames = 0;
  const std::string why = Problems(o);
  EXPECT_TRUE(Names(why, "backoff_max_s")) << why;
  EXPECT_TRUE(Names(why, "preview_interval_s")) << why;
  EXPECT_TRUE(Names(why, "pipeline.queue_frames")) << why;
  o = {};
  o.camera.name = "cam0";
  o.offline_after_s = -1;
  const std::string what = InputErrorOf([&] { CameraRunner runner(0, o, nullptr, nullptr); });
  EXPECT_EQ(what.rfind("camera cam0 runner options: offline_after_s: ", 0), 0u) << what;
}

TEST(StationOptions, ControlServerAndLabels) {
  ControlServerOptions c;
  c.config.port = 70000;
  c.max_event_streams = -1;
  c.http_threads = 0;
  const std::string why = Problems(c);
  EXPECT_TRUE(Names(why, "config.port")) << why;
  EXPECT_TRUE(Names(why, "max_event_streams")) << why;
  EXPECT_TRUE(Names(why, "http_threads")) << why;

  ConsoleLabelsOptions l;
  l.candidate_rows = 0;
  l.min_labels = 1;
  const std::string labels = Problems(l);
  EXPECT_TRUE(Names(labels, "candidate_rows")) << labels;
  EXPECT_TRUE(Names(labels, "min_labels")) << labels;
  l = {};
  l.threads = 0;
  const std::string what = InputErrorOf([&] { ConsoleLabels console(api::Context{}, l); });
  EXPECT_EQ(what, "labels options: threads: expected at least 1 thread, got 0");
}

}  // namespace
}  // namespace ss
