// The station config's keying section reaches the keyers (StationConfig::pipeline ->
// CameraPipeline): a changed config value changes what the pipeline's keyer makes of the same
// frame (docs/keying.md, "From the station config").
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "config/station_config.h"
#include "core/error.h"
#include "core/option_checks.h"
#include "core/options_binder.h"
#include "pipeline/key/chroma_keyer.h"
#include "pipeline/key/clean_plate_keyer.h"
#include "pipeline/key/keyer_registry.h"
#include "pipeline/run/camera_pipeline.h"
#include "tests/pipeline/key_scene.h"

namespace ss {
namespace {

using testing::KeyScene;
using testing::SceneFrame;
using testing::SceneOptions;
using testing::SceneSubject;

// A pinhole camera 1.4 m from the floor origin, looking down at it, for the scene's 640x480 frames.
CameraModel Camera() {
  const Eigen::Vector3d centre(0.0, -0.9, 1.1), target(0.0, 0.0, 0.0);
  const Eigen::Vector3d z = (target - centre).normalized();
  const Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ()).normalized();
  Rigid3 cam_from_ground;
  cam_from_ground.rotation.row(0) = x;
  cam_from_ground.rotation.row(1) = z.cross(x);
  cam_from_ground.rotation.row(2) = z;
  cam_from_ground.translation = -(cam_from_ground.rotation * centre);
  return CameraModel("LENSMODEL_PINHOLE", {560, 560, 319.5, 239.5}, 640, 480, cam_from_ground);
}

struct Keyed {
  Matte matte;
  const CameraPipeline* pipeline = nullptr;
  double alpha_sum = 0;   // of 255
  double shadow_sum = 0;  // of 255
  double rim_green = 0;   // mean G of the colour layer on the subject's spilled rim
};

class KeyerConfig : public ::testing::Test {
 protected:
  // Trains a pipeline made from `config` on the scene's empty frames and keys one frame.
  Keyed Key(const StationConfig& config, bool green = true) {
    SceneOptions so;
    so.green = green;
    const KeyScene scene(so);
    SceneSubject s;
    s.centre = {320.5, 250.5};
    std::vector<cv::Mat> empty;
    empty.reserve(4);
    for (int i = 0; i < 4; ++i) empty.push_back(scene.Empty(100 + i));
    const SceneFrame f = scene.Render({s}, 7);
    GroundPolygon floor({{-0.6, -0.4}, {0.6, -0.4}, {0.6, 0.4}, {-0.6, 0.4}});
    CameraPipelineOptions options = config.pipeline;
    // auto is resolved per bank (ChooseBankScale); any scale does here
    options.rectify.px_per_m = 800;
    pipelines_.emplace_back(std::make_unique<CameraPipeline>("cam0", 1, Camera(), floor, options));
    CameraPipeline& p = *pipelines_.back();
    p.Train(empty);
    Keyed k;
    k.pipeline = &p;
    p.keyer().Key(f.bgr, k.matte);
    k.alpha_sum = cv::sum(k.matte.alpha)[0];
    k.shadow_sum = cv::sum(k.matte.shadow)[0];
    std::vector<cv::Mat> channels;
    cv::split(k.matte.colour, channels);
    const cv::Mat rim = f.rim & (k.matte.alpha == 255);
    if (cv::countNonZero(rim) > 0) k.rim_green = cv::mean(channels[1], rim)[0];
    return k;
  }
  std::vector<std::unique_ptr<CameraPipeline>> pipelines_;
};

TEST_F(KeyerConfig, DespillFollowsTheConfig) {
  StationConfig config;
  const Keyed on = Key(config);
  ASSERT_GT(on.alpha_sum, 0);
  config.pipeline.keying->despill.strength = 0.5;
  const Keyed half = Key(config);
  config.pipeline.keying->despill.enabled = false;
  const Keyed off = Key(config);
  // The rim's green spill above the despill limit (~16 levels on average): all of it removed,
  // half of it, none.
  EXPECT_GT(half.rim_green, on.rim_green + 5);
  EXPECT_GT(off.rim_green, half.rim_green + 5);
  EXPECT_EQ(on.alpha_sum, off.alpha_sum);  // despill changes colour only
}

TEST_F(KeyerConfig, ShadowFollowsTheConfig) {
  StationConfig config;
  const Keyed on = Key(config);
  ASSERT_GT(on.shadow_sum, 255 * 200.0) << "the scene's subject casts a contact shadow";
  config.pipeline.keying->shadow.min_darkening = 0.3;
  const Keyed faint_dropped = Key(config);
  EXPECT_LT(faint_dropped.shadow_sum, 0.9 * on.shadow_sum);
  config.pipeline.keying = KeyingConfig{};
  config.pipeline.keying->shadow.enabled = false;
  const Keyed off = Key(config);
  EXPECT_EQ(off.shadow_sum, 0);
  EXPECT_GT(off.alpha_sum, 0);
  // The reach in metres becomes grid cells at the camera's scale (~300 px per metre at the floor).
  config.pipeline.keying = KeyingConfig{};
  config.pipeline.keying->shadow_reach_m = 0.05;
  const int near = Key(config).pipeline->keyer().grid().shadow_reach_cells;
  config.pipeline.keying->shadow_reach_m = 0.5;
  const int far = Key(config).pipeline->keyer().grid().shadow_reach_cells;
  EXPECT_GE(near, 1);
  EXPECT_GT(far, 5 * near);
}

TEST_F(KeyerConfig, ChromaThresholdsFollowTheConfig) {
  StationConfig config;
  const Keyed defaults = Key(config);
  ASSERT_GT(defaults.alpha_sum, 0);
  // A key threshold far below the green's own (~105 levels): the soft, greenish edge falls to
  // background (about 2.5% of the subject's alpha).
  config.pipeline.keying->Block<ChromaKeyBlock>("chroma") = {0, 15};
  const Keyed tight = Key(config);
  EXPECT_LT(tight.alpha_sum, 0.99 * defaults.alpha_sum);
  EXPECT_GT(tight.alpha_sum, 0.9 * defaults.alpha_sum);
}

TEST_F(KeyerConfig, CleanPlateThresholdsFollowTheConfig) {
  StationConfig config;
  config.pipeline.keying->method = "clean_plate";
  const Keyed defaults = Key(config, /*green=*/false);
  ASSERT_GT(defaults.alpha_sum, 0);
  // A wider tolerance and ramp (in noise sigmas) key less of the frame as subject.
  config.pipeline.keying->Block<CleanPlateKeyBlock>("clean_plate") = {12, 40};
  const Keyed loose = Key(config, false);
  EXPECT_LT(loose.alpha_sum, 0.97 * defaults.alpha_sum);
}

// A keyer registered as the built-in ones are (pipeline/key/keyer_registry.h) is chosen by the
// config's keying.method, its own keys bound, checked and documented by the config, with nothing
// in config/ or pipeline/key/keying_keys.cc naming it (issue 36): here the chroma keyer under
// another name, whose own block `twin:` holds its thresholds.
struct TwinKeyer : ChromaKeyer {
  using ChromaKeyer::ChromaKeyer;
  std::string name() const override { return "twin"; }
};

// The twin's own block: a struct of its own, which pipeline/key/keying_config.h does not name.
struct TwinBlock {
  double low = 20, high = 60;
  bool operator==(const TwinBlock&) const = default;
};

ChromaKeyerOptions TwinOptionsFrom(const KeyingConfig& k) {
  ChromaKeyerOptions o = ChromaKeyerOptionsFrom(k);
  o.key_low_levels = k.Block<TwinBlock>("twin").low;
  o.key_high_levels = k.Block<TwinBlock>("twin").high;
  return o;
}

TEST_F(KeyerConfig, AKeyerRegisteredApartIsChosenByTheConfig) {
  const auto keys = [](OptionsBinder& b, KeyingConfig& k) {
    auto& block = k.Block<TwinBlock>("twin");
    b.Add("twin.low", &block.low, "a level from 0 to 255", "where alpha falls")
        .Rule(Between(0, 255))
        .Add("twin.high", &block.high, "a level from 0 to 255", "where it is 0")
        .Rule(Between(0, 255));
  };
  const auto check = [](const KeyingConfig& k, std::string* why) {
    OptionProblems problem(why);
    problem(k.Block<TwinBlock>("twin").low < k.Block<TwinBlock>("twin").high, "twin.high",
            "must be above low");
    return problem.ok();
  };
  RegisterKeyerType<TwinKeyer>("twin", "the chroma keyer again, under another name",
                               TwinOptionsFrom, AnyBlock::Of(TwinBlock{}), keys, check);
  EXPECT_EQ(KeyingConfig{}.Block<TwinBlock>("twin"), TwinBlock{});  // every config holds it
  EXPECT_THROW(RegisterKeyerType<TwinKeyer>("twin", "again", ChromaKeyerOptionsFrom), WorkError);
  const std::string camera =
      "cameras:\n  - name: cam0\n    source: v4l2\n    device: /dev/video0\n";
  const StationConfig config =
      ParseStationConfig(camera + "keying:\n  method: twin\n", "station.yaml", "/tmp");
  ASSERT_TRUE(config.pipeline.keying);
  EXPECT_EQ(config.pipeline.keying->method, "twin");
  StationConfig chroma;
  const Keyed twin = Key(config), by_chroma = Key(chroma);
  EXPECT_EQ(twin.pipeline->keyer().name(), "twin");
  EXPECT_GT(twin.alpha_sum, 0);
  EXPECT_EQ(twin.alpha_sum, by_chroma.alpha_sum);  // the same keyer, the same options
  // Its own keys: read into its block, documented, their bounds and its rule named at the key.
  const StationConfig tight = ParseStationConfig(
      camera + "keying:\n  method: twin\n  twin: {low: 0, high: 15}\n", "station.yaml", "/tmp");
  EXPECT_EQ(tight.pipeline.keying->Block<TwinBlock>("twin"), (TwinBlock{0, 15}));
  EXPECT_EQ(tight.pipeline.keying->Block<ChromaKeyBlock>("chroma"), ChromaKeyBlock{})
      << "the chroma keyer's block is its own";
  EXPECT_FALSE(*tight.pipeline.keying == *config.pipeline.keying) << "compared by its block";
  EXPECT_LT(Key(tight).alpha_sum, 0.99 * twin.alpha_sum) << "its keys reach the keyer";
  EXPECT_NE(ConfigKeysMarkdown().find("| `twin.low` | number 0..255 | `20` | where alpha falls |"),
            std::string::npos)
      << ConfigKeysMarkdown();
  const auto refusal = [&](const std::string& block) {
    try {
      ParseStationConfig(camera + "keying:\n  method: twin\n  twin: " + block + "\n",
                         "station.yaml", "/tmp");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("taken");
  };
  EXPECT_NE(refusal("{low: 300}")
                .find("station.yaml:7: keying.twin.low: expected a level from 0 to 255, got 300"),
            std::string::npos)
      << refusal("{low: 300}");
  EXPECT_NE(
      refusal("{low: 80, high: 40}").find("station.yaml:7: keying.twin.high: must be above low"),
      std::string::npos)
      << refusal("{low: 80, high: 40}");
  EXPECT_EQ(refusal("{low: 300, high: 40}").find("twin.high"), std::string::npos)
      << "no order against a refused bound: " << refusal("{low: 300, high: 40}");
  try {
    ParseStationConfig(camera + "keying:\n  method: luma\n", "station.yaml", "/tmp");
    ADD_FAILURE() << "an unknown keyer was taken";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(
                  "station.yaml:6: keying.method: expected one of chroma, clean_plate, twin, got "
                  "\"luma\""),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace ss
