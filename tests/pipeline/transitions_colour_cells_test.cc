// The colour_cells stage-2 variant, shipped as an option (velocity AND alpha difference AND the
// count of colour-different cells): the feature is right on hand-made pairs and its SIMD kernel
// agrees with the plain loop, the filter never rejects a pair the full evaluation keeps, the
// weights file carries the variant, and its fit picks the thresholds the counts call for.
#include <gtest/gtest.h>

#include <array>
#include <random>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "pipeline/transitions/builder.h"
#include "pipeline/transitions/classifier.h"
#include "pipeline/transitions/colour_cells_training.h"
#include "pipeline/transitions/sprite_store.h"
#include "pipeline/transitions/synthetic.h"
#include "tests/pipeline/hand_made_sprites.h"
#include "tests/pipeline/transitions_test_util.h"

namespace ss {
namespace {

using testing::Cell;
using testing::CellPerPixel;
using testing::Rectangle;
using testing::Sprite;

TransitionWeights CellsWeights(const ComparisonWindow& window, double max_velocity,
                               double max_alpha_cells, int max_cells) {
  TransitionWeights w = testing::UnitWeights({1, 1, 1, 1, 1, 1}, max_velocity, 1);
  w.window = window;
  w.stage1_weights = {1, 0, 0, 0};  // the velocity ball: passes every pair stage 2 can keep
  w.stage2_variant = Stage2Variant::kColourCells;
  w.colour_cells_max_velocity_mps = max_velocity;
  w.colour_cells_max_alpha_cells = max_alpha_cells;
  w.colour_cells_max_cells = max_cells;
  return w;
}

ComparisonWindow OnePixelContact() {
  ComparisonWindow window;
  window.width_m = 0.24;
  window.height_m = 0.18;
  window.cells_x = 60;
  window.cells_y = 45;
  window.align = HorizontalAlignment::kContactPoint;
  return window;
}

RgbaBillboard Recolour(RgbaBillboard b, const std::vector<Cell>& cells,
                       const std::array<uint8_t, 3>& rgb) {
  for (const Cell& c : cells) {
    uint8_t* p = b.rgba.data() + (static_cast<size_t>(c.y) * 32 + c.x) * 4;
    p[0] = rgb[0];
    p[1] = rgb[1];
    p[2] = rgb[2];
  }
  return b;
}

TEST(TransitionColourCells, FeatureOnHandMadePairs) {
  const RgbaBillboard body = Sprite(Rectangle(8, 10, 20, 32, 255));  // colour {200, 100, 50}
  // 3 x 2 cells with dR + dG + dB = 110 + 0 + 0, and 2 x 1 more with exactly 90 (the step).
  RgbaBillboard patches = Recolour(body, Rectangle(9, 12, 12, 14, 255), {90, 100, 50});
  patches = Recolour(patches, Rectangle(15, 20, 17, 21, 255), {200, 40, 20});
  // 6 cells at 89: below the step.
  const RgbaBillboard faint = Recolour(body, Rectangle(9, 12, 12, 14, 255), {150, 80, 31});
  // the patch at alpha 127 in one sprite: not opaque in both
  RgbaBillboard thin = Recolour(body, Rectangle(9, 12, 12, 14, 255), {90, 100, 50});
  for (const Cell& c : Rectangle(9, 12, 12, 14, 0)) thin.rgba[(c.y * 32 + c.x) * 4 + 3] = 127;
  const RgbaBillboard moved = Sprite(Rectangle(9, 10, 21, 32, 255));  // one column right
  const std::vector<RgbaBillboard> sprites = {body, patches, faint, thin, moved};
  std::vector<SpriteInput> inputs;
  for (size_t k = 0; k < sprites.size(); ++k) {
    CheapFeatures cheap;
    cheap.velocity_x_mps = 0.01 * static_cast<double>(k);
    inputs.push_back(
        {static_cast<int64_t>(k + 1), static_cast<int64_t>(k + 1), cheap, &sprites[k]});
  }
  SpriteStore s(CellPerPixel(), 100.0);
  s.Append(inputs);
  const int stride = s.window().PlaneStride();
  auto cells = [&](int32_t i, int32_t j) {
    return ColourCellCount(s.image(i), s.image(j), stride);
  };
  EXPECT_EQ(cells(0, 1), 8);  // 6 + 2 (90 counts)
  EXPECT_EQ(cells(0, 2), 0);  // 89 does not
  EXPECT_EQ(cells(0, 3), 0);  // alpha 127 is not opaque
  EXPECT_EQ(cells(1, 3), 2);  // the 2 x 1 patch; the 3 x 2 one is not opaque in 3
  EXPECT_EQ(cells(0, 4), 0);  // the silhouettes differ, the colours where both are opaque do not
  for (int32_t i = 0; i < s.size(); ++i) {
    EXPECT_EQ(cells(i, i), 0);
    for (int32_t j = 0; j < s.size(); ++j) {
      EXPECT_EQ(cells(i, j), cells(j, i));
      EXPECT_EQ(cells(i, j), ColourCellCountScalar(s.image(i), s.image(j), stride));
    }
  }

  // Stage 2 with the bounds 0.025 m/s, 30 cells of alpha difference, 6 colour cells.
  const TransitionClassifier c(CellsWeights(CellPerPixel(), 0.025, 30, 6));
  ASSERT_TRUE(c.colour_cells());
  EXPECT_EQ(c.colour_cells_alpha_limit(), 30u * 255u);
  double d = -1;
  EXPECT_FALSE(c.Stage2(s, 0, 1, &d));  // 8 colour cells > 6
  EXPECT_TRUE(c.Stage2(s, 0, 2, &d));   // velocity 0.02, nothing else differs
  EXPECT_NEAR(d, 0.02 / 0.025, 1e-12);
  EXPECT_FALSE(c.Stage2(s, 1, 4, &d));  // velocity 0.03 > 0.025
  const TransitionClassifier wide(CellsWeights(CellPerPixel(), 0.05, 30, 8));
  EXPECT_TRUE(wide.Stage2(s, 0, 1, &d));  // 8 <= 8, velocity 0.01
  EXPECT_NEAR(d, 1.0, 1e-12);
  EXPECT_FALSE(wide.Stage2(s, 0, 4, &d));  // alpha: 22 cells appear, 22 disappear = 44 > 30
  // 44 cells of alpha difference: kept at a bound of 44, not at 43.
  double d04 = -1, d40 = -1;
  EXPECT_TRUE(
      TransitionClassifier(CellsWeights(CellPerPixel(), 0.05, 44, 8)).Stage2(s, 0, 4, &d04));
  EXPECT_TRUE(
      TransitionClassifier(CellsWeights(CellPerPixel(), 0.05, 44, 8)).Stage2(s, 4, 0, &d40));
  EXPECT_EQ(d04, d40);
  EXPECT_NEAR(d04, 1.0, 1e-12);  // the alpha ratio 44 / 44
  EXPECT_FALSE(TransitionClassifier(CellsWeights(CellPerPixel(), 0.05, 43, 8)).Stage2(s, 0, 4, &d));
}

TEST(TransitionColourCells, SimdAgreesWithThePlainLoop) {
  std::mt19937 rng(5);
  const ComparisonWindow window = OnePixelContact();
  const int stride = window.PlaneStride();
  std::vector<uint8_t> a(window.ImageBytes()), b(window.ImageBytes());
  for (int round = 0; round < 50; ++round) {
    for (size_t k = 0; k < a.size(); ++k) {
      a[k] = static_cast<uint8_t>(rng());
      // near a: differences around the step
      b[k] =
          static_cast<uint8_t>(std::clamp<int>(a[k] + static_cast<int>(rng() % 81) - 40, 0, 255));
    }
    const int simd = ColourCellCount(a.data(), b.data(), stride);
    EXPECT_EQ(simd, ColourCellCountScalar(a.data(), b.data(), stride)) << round;
    EXPECT_EQ(simd, ColourCellCount(b.data(), a.data(), stride));
  }
}

// On generated sprites in the 1 px contact window: SignatureRejects never rejects a pair Stage2
// keeps, it does reject, stage 1 passes every kept pair, and the builder keeps exactly what a
// linear scan keeps.
TEST(TransitionColourCells, FilterIsExactOnSyntheticSprites) {
  SyntheticSpriteOptions so;
  so.frames = 120;
  so.seed = 9;
  const auto sprites = MakeSyntheticSprites(so);
  const ComparisonWindow window = OnePixelContact();
  SpriteStore store(window, so.px_per_m);
  store.Append(AsSpriteInputs(sprites), 2);
  for (const double alpha_cells : {20.0, 80.0, 300.0}) {
    const TransitionWeights w = CellsWeights(window, 0.05, alpha_cells, 10);
    const TransitionClassifier c(w);
    int64_t kept = 0, rejected_by_filter = 0;
    for (int32_t i = 0; i < store.size(); ++i) {
      for (int32_t j = 0; j < store.size(); ++j) {
        if (i == j) continue;
        double d = -1, e = -1;
        const bool full = c.Stage2(store, i, j, &d);
        ASSERT_EQ(full, c.Stage2(store, j, i, &e));
        const bool filter = c.SignatureRejects(store, i, j);
        ASSERT_FALSE(full && filter) << i << " " << j;
        rejected_by_filter += filter;
        if (full) {
          ASSERT_EQ(d, e);
          ASSERT_LE(d, 1.0);
          ASSERT_TRUE(c.Stage1Accepts(store.cheap(i), store.cheap(j)));
        }
        kept += full;
      }
    }
    EXPECT_GT(kept, 0) << alpha_cells;
    EXPECT_GT(rejected_by_filter, 0) << alpha_cells;
    TransitionBuilder builder(w, so.px_per_m);
    builder.BuildFromScratch(AsSpriteInputs(sprites), BuildOptions{.threads = 2});
    const BuildStats& st = builder.stats();
    EXPECT_EQ(st.stage1_candidates, st.signature_rejected + st.stage2_evaluations);
    EXPECT_EQ(st.kept_pairs, kept / 2) << "the builder keeps exactly the pairs a linear scan keeps";
  }
}

std::string ErrorOf(const std::string& text) {
  try {
    ParseWeights(text, "w.json");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(TransitionColourCells, WeightsFileCarriesTheVariant) {
  const TransitionWeights w = CellsWeights(OnePixelContact(), 0.04, 120, 7);
  const std::string text = WeightsToJson(w);
  const nlohmann::json good = nlohmann::json::parse(text);
  EXPECT_EQ(good["version"], 2);
  EXPECT_EQ(good["stage2"]["variant"], "colour_cells");
  const TransitionWeights back = ParseWeights(text, "w.json");
  EXPECT_EQ(back.stage2_variant, Stage2Variant::kColourCells);
  EXPECT_EQ(back.colour_cells_max_velocity_mps, 0.04);
  EXPECT_EQ(back.colour_cells_max_alpha_cells, 120);
  EXPECT_EQ(back.colour_cells_max_cells, 7);
  EXPECT_EQ(WeightsToJson(back), text);
  auto edited = [&](auto change) {
    nlohmann::json j = good;
    change(j);
    return ErrorOf(j.dump());
  };
  EXPECT_NE(edited([](nlohmann::json& j) {
              j["stage2"]["colour_cells"]["max_colour_cells"] = -1;
            }).find("w.json: stage2.colour_cells.max_colour_cells:"),
            std::string::npos);
  EXPECT_NE(edited([](nlohmann::json& j) {
              j["stage2"]["colour_cells"]["max_alpha_cells"] = -3;
            }).find("w.json: stage2.colour_cells.max_alpha_cells:"),
            std::string::npos);
  EXPECT_NE(edited([](nlohmann::json& j) {
              j["stage2"]["colour_cells"].erase("max_velocity_mps");
            }).find("w.json: stage2.colour_cells.max_velocity_mps: missing"),
            std::string::npos);
  // The shipped default is this variant, and its stage 1 is the velocity ball of its bound.
  const TransitionClassifier shipped(ColourCellsWeights());
  ASSERT_TRUE(shipped.colour_cells());
  CheapFeatures a, b;
  b.velocity_x_mps = ColourCellsWeights().colour_cells_max_velocity_mps;
  b.colour[0] = b.colour[1] = b.colour[2] = 250;  // other cheap features do not count
  b.area_m2 = 1;
  EXPECT_TRUE(shipped.Stage1Accepts(a, b));
  b.velocity_x_mps *= 1.001;
  EXPECT_FALSE(shipped.Stage1Accepts(a, b));
}

TEST(TransitionColourCells, FitPicksTheThresholdsTheCountsCallFor) {
  // On labels alone (a 50/50 world): accepts have velocity 0.01, alpha 10, 2 cells; rejects
  // differ in one measurement each. The best F1 (1.0) keeps all accepts and no reject, and
  // among the perfect points the smallest alpha bound is chosen.
  std::vector<ColourCellsMeasure> positives(20, {0.01, 10, 2});
  std::vector<ColourCellsMeasure> negatives = {
      {0.05, 10, 2}, {0.01, 600, 2}, {0.01, 10, 12}, {0.2, 1000, 30}};
  TransitionWeights w = PaperWeights();
  const ColourCellsFit fit = FitColourCellsOnLabels(positives, negatives, {}, &w);
  EXPECT_EQ(fit.f1, 1.0);
  EXPECT_EQ(fit.max_alpha_cells, 20);  // the grid's smallest bound above 10
  EXPECT_LT(fit.max_velocity_mps, 0.05);
  EXPECT_GE(fit.max_velocity_mps, 0.01);
  EXPECT_GE(fit.max_colour_cells, 2);
  EXPECT_LT(fit.max_colour_cells, 12);
  EXPECT_EQ(w.stage2_variant, Stage2Variant::kColourCells);
  EXPECT_EQ(w.colour_cells_max_cells, fit.max_colour_cells);
  // Stage 1 became the velocity ball.
  const TransitionClassifier c(w);
  CheapFeatures a, b;
  b.velocity_x_mps = fit.max_velocity_mps;
  EXPECT_TRUE(c.Stage1Accepts(a, b));
  b.velocity_x_mps = 0.05;
  EXPECT_FALSE(c.Stage1Accepts(a, b));
  EXPECT_THROW(FitColourCellsOnLabels(positives, {}, {}, &w), InputError);
}

}  // namespace
}  // namespace ss
