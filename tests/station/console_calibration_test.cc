// The console's calibration wizard (station/console_calibration.h) on a running station: which
// of its cameras the status calls online. A camera whose keyer failed is in error but still
// streams (for preview and recording): its wizard is fed and captures views, so the page must
// not call it offline (issue 41: a wizard that captures, shown as blind and stale).
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "station/console_calibration.h"
#include "station/station_host.h"
#include "station/station_status.h"
#include "tests/station/replay_station.h"
#include "tests/support/test_support.h"

// After every Eigen header (resolv.h's `_res` macro breaks Eigen: station/api_part.h).
#include <httplib.h>

namespace ss {
namespace {

using ss::testing::ScratchDir;

class ConsoleCalibrationTest : public ::testing::Test {
 protected:
  void SetUp() override {
    host_ = std::make_unique<StationHost>(ss::testing::OneReplayCamera(scratch_),
                                          std::vector<std::string>{});
    host_->Start();
    api::Context context;
    context.host = host_.get();
    context.station = [h = host_.get()] { return h->current(); };
    calibration_ = std::make_unique<ConsoleCalibration>(context);
  }
  void TearDown() override {
    if (calibration_) calibration_->Stop();
    calibration_.reset();
    if (host_) host_->Stop();
  }

  // POST /api/calibration/start with `body`, as the control server calls the route.
  void StartWizard(const nlohmann::json& body) {
    for (api::Route& r : calibration_->Routes()) {
      if (r.method != "POST" || r.pattern != "/api/calibration/start") continue;
      httplib::Request req;
      req.method = "POST";
      req.body = body.dump();
      httplib::Response res;
      r.handler(req, res);
      ASSERT_EQ(res.status, 200) << res.body;
      return;
    }
    FAIL() << "no start route";
  }

  // The station's status as the control server sends it, with cam0 set as `edit` says, and
  // the calibration members added.
  nlohmann::json StatusWith(const nlohmann::json& edit) {
    nlohmann::json status = StatusToJson(host_->current()->Status());
    status["cameras"][0].update(edit);
    calibration_->AddStatus(status);
    return status["calibration"];
  }

  ScratchDir scratch_;
  std::unique_ptr<StationHost> host_;
  std::unique_ptr<ConsoleCalibration> calibration_;
};

TEST_F(ConsoleCalibrationTest, ACameraInErrorWhoseFramesStillComeIsOnline) {
  StartWizard({{"board", "chessboard:10x7:0.03"}});
  // Its keyer failed (a chroma key on a background that is not green): the camera is in error,
  // and streams on at 30 frames a second.
  const nlohmann::json streaming =
      StatusWith({{"state", "error"},
                  {"fps", 30.0},
                  {"message",
                   "learning the empty enclosure failed: chroma keyer training: only "
                   "0% of the empty enclosure is green enough"}});
  ASSERT_EQ(streaming["cameras"].size(), 1u) << streaming.dump(1);
  EXPECT_EQ(streaming["cameras"][0]["online"], true) << streaming.dump(1);
  EXPECT_EQ(streaming["cameras"][0]["message"], "") << "the keyer is not the wizard's problem";
  EXPECT_TRUE(streaming["error"].is_null()) << streaming["error"];

  // In error with no frame for 2 s (its capture thread ended): offline, with the station's
  // reason.
  const nlohmann::json silent =
      StatusWith({{"state", "error"}, {"fps", 0.0}, {"message", "the source failed"}});
  EXPECT_EQ(silent["cameras"][0]["online"], false) << silent.dump(1);
  EXPECT_EQ(silent["cameras"][0]["message"], "error: the source failed");
  EXPECT_EQ(silent["error"],
            "cam0 delivers no frames (error: the source failed); the views captured so far are "
            "kept");

  // Offline (the camera's own state): offline whatever its last rate.
  const nlohmann::json offline =
      StatusWith({{"state", "offline"}, {"fps", 30.0}, {"message", "no frame for 3.0 s"}});
  EXPECT_EQ(offline["cameras"][0]["online"], false) << offline.dump(1);
}

}  // namespace
}  // namespace ss
