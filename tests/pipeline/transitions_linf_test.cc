// The linf stage-2 variant (velocity AND the largest cell alpha difference) and the
// colour_blob one (velocity AND the largest blob of colour differences): the features are
// symmetric and right on hand-made pairs, the filters never reject a pair the full evaluation
// accepts, and the weights file carries the variant (version 2) while version-1 files load
// as before.
#include <gtest/gtest.h>

#include <array>
#include <functional>
#include <random>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "pipeline/transitions/builder.h"
#include "pipeline/transitions/classifier.h"
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

// Linf weights: stage 1 = the velocity bound alone (so it passes every pair stage 2 can keep).
TransitionWeights LinfWeights(const ComparisonWindow& window, double max_velocity,
                              double max_alpha) {
  TransitionWeights w = testing::UnitWeights({1, 1, 1, 1, 1, 1}, max_velocity, 1);
  w.window = window;
  w.stage1_weights = {1, 0, 0, 0};
  w.stage2_variant = Stage2Variant::kLinf;
  w.linf_max_velocity_mps = max_velocity;
  w.linf_max_alpha = max_alpha;
  return w;
}

int Linf(const SpriteStore& s, int32_t i, int32_t j) {
  return MaxAlphaDifference(s.image(i), s.image(j), s.window().PlaneStride());
}

TEST(TransitionLinf, FeatureOnHandMadePairs) {
  std::vector<RgbaBillboard> sprites = {
      Sprite(Rectangle(8, 10, 20, 32, 255)),  // 0: body
      Sprite(Rectangle(8, 10, 20, 32, 255)),  // 1: the same
      Sprite(Rectangle(8, 10, 20, 32, 185)),  // 2: the same, fainter by 70
      Sprite(Rectangle(9, 10, 21, 32, 255)),  // 3: 0 moved one cell right
      Sprite([] {                             // 4: 0 with one cell fainter by 30
        auto c = Rectangle(8, 10, 20, 32, 255);
        c[5].alpha = 225;
        return c;
      }()),
  };
  std::vector<SpriteInput> inputs;
  for (size_t k = 0; k < sprites.size(); ++k) {
    CheapFeatures cheap;
    cheap.velocity_x_mps = 0.01 * static_cast<double>(k);  // velocity differences 0.01 per index
    inputs.push_back(
        {static_cast<int64_t>(k + 1), static_cast<int64_t>(k + 1), cheap, &sprites[k]});
  }
  SpriteStore s(CellPerPixel(), 100.0);
  s.Append(inputs);
  EXPECT_EQ(Linf(s, 0, 1), 0);
  EXPECT_EQ(Linf(s, 0, 2), 70);
  EXPECT_EQ(Linf(s, 0, 3), 255);  // a column appears, another disappears
  EXPECT_EQ(Linf(s, 0, 4), 30);
  EXPECT_EQ(Linf(s, 2, 4), 70);
  for (int32_t i = 0; i < s.size(); ++i) {
    EXPECT_EQ(Linf(s, i, i), 0);
    for (int32_t j = 0; j < s.size(); ++j) EXPECT_EQ(Linf(s, i, j), Linf(s, j, i));
  }

  // Stage 2 with the bounds 0.025 m/s and 40/255: kept iff both hold; D is the larger ratio.
  const TransitionClassifier c(LinfWeights(CellPerPixel(), 0.025, 40.0 / 255));
  ASSERT_TRUE(c.linf());
  EXPECT_EQ(c.linf_alpha_limit(), 40);
  double d = -1;
  EXPECT_TRUE(c.Stage2(s, 0, 1, &d));  // velocity 0.01, linf 0
  EXPECT_NEAR(d, 0.01 / 0.025, 1e-12);
  EXPECT_FALSE(c.Stage2(s, 0, 2, &d));          // linf 70 > 40
  EXPECT_FALSE(c.Stage2(s, 0, 3, &d));          // linf 255
  EXPECT_FALSE(c.Stage2(s, 0, 4, &d));          // linf 30 but velocity 0.04 > 0.025
  EXPECT_TRUE(c.Stage2(s, 3, 4, &d) == false);  // linf 255
  const TransitionClassifier loose(LinfWeights(CellPerPixel(), 0.05, 40.0 / 255));
  double d04 = -1, d40 = -1;
  EXPECT_TRUE(loose.Stage2(s, 0, 4, &d04));  // velocity 0.04 <= 0.05, linf 30 <= 40
  EXPECT_TRUE(loose.Stage2(s, 4, 0, &d40));
  EXPECT_EQ(d04, d40);
  EXPECT_NEAR(d04, std::max(0.04 / 0.05, 30.0 / 40.0), 1e-12);
}

std::vector<RgbaBillboard> RandomSprites(std::mt19937& rng, int count) {
  std::vector<RgbaBillboard> sprites;
  for (int k = 0; k < count; ++k) {
    std::vector<Cell> cells;
    const int blobs = 1 + static_cast<int>(rng() % 4);
    for (int b = 0; b < blobs; ++b) {
      const int x0 = rng() % 26, y0 = rng() % 26;
      for (const Cell& c : Rectangle(x0, y0, x0 + 1 + rng() % 6, y0 + 1 + rng() % 6, rng() % 256))
        cells.push_back(c);
    }
    sprites.push_back(Sprite(cells));
  }
  return sprites;
}

TEST(TransitionLinf, BoundNeverRejectsWhatTheFullEvaluationAccepts) {
  std::mt19937 rng(31);
  const std::vector<RgbaBillboard> sprites = RandomSprites(rng, 60);
  std::vector<SpriteInput> inputs;
  for (size_t k = 0; k < sprites.size(); ++k) {
    inputs.push_back({static_cast<int64_t>(k + 1), static_cast<int64_t>(k + 1), {}, &sprites[k]});
  }
  SpriteStore s(CellPerPixel(), 100.0);
  s.Append(inputs);
  for (const int limit : {0, 10, 60, 128, 254}) {
    int proven = 0, exceeding = 0;
    for (int32_t i = 0; i < s.size(); ++i) {
      for (int32_t j = 0; j < s.size(); ++j) {
        const bool bound = s.SignatureLinfExceeds(i, j, limit);
        ASSERT_EQ(bound, s.SignatureLinfExceeds(j, i, limit));
        const bool exceeds = Linf(s, i, j) > limit;
        ASSERT_FALSE(bound && !exceeds) << i << " " << j << " limit " << limit;
        proven += bound;
        exceeding += exceeds;
      }
    }
    if (limit <= 60) {
      EXPECT_GT(proven, exceeding / 10) << "limit " << limit << ": the bound must prove something";
    }
  }
}

// On generated sprites in a 1 px contact-aligned window (as measured in bench/RESULTS.md):
// SignatureRejects never rejects a pair Stage2 keeps, it rejects most pairs, and the builder's
// counts add up.
TEST(TransitionLinf, FilterIsExactOnSyntheticSprites) {
  SyntheticSpriteOptions so;
  so.frames = 150;
  so.seed = 8;
  const auto sprites = MakeSyntheticSprites(so);
  ComparisonWindow window;
  window.width_m = 0.24;
  window.height_m = 0.18;
  window.cells_x = 60;
  window.cells_y = 45;
  window.align = HorizontalAlignment::kContactPoint;
  SpriteStore store(window, so.px_per_m);
  store.Append(AsSpriteInputs(sprites), 2);
  for (const double max_alpha : {0.3, 0.6, 0.9}) {
    const TransitionWeights w = LinfWeights(window, 0.05, max_alpha);
    const TransitionClassifier c(w);
    int64_t kept = 0, rejected = 0, filtered = 0;
    for (int32_t i = 0; i < store.size(); ++i) {
      for (int32_t j = 0; j < store.size(); ++j) {
        if (i == j) continue;
        double d = -1;
        const bool full = c.Stage2(store, i, j, &d);
        const bool excluded = c.SignatureRejects(store, i, j);
        ASSERT_FALSE(excluded && full) << i << " " << j << " max_alpha " << max_alpha;
        ASSERT_EQ(excluded, c.SignatureRejects(store, j, i));
        if (full) {
          ASSERT_GE(d, 0.0);
          ASSERT_LE(d, 1.0);
          ASSERT_TRUE(c.Stage1Accepts(store.cheap(i), store.cheap(j)))
              << "stage 1 must pass what stage 2 keeps";
        }
        (full ? kept : rejected) += 1;
        filtered += excluded;
      }
    }
    EXPECT_GT(kept, 0) << max_alpha;
    EXPECT_GT(filtered, rejected / 2) << max_alpha;

    TransitionBuilder builder(w, so.px_per_m);
    builder.BuildFromScratch(AsSpriteInputs(sprites), BuildOptions{.threads = 2});
    const BuildStats& st = builder.stats();
    EXPECT_EQ(st.stage1_candidates, st.signature_rejected + st.stage2_evaluations);
    EXPECT_GE(st.stage2_evaluations, st.kept_pairs);
    EXPECT_EQ(st.kept_pairs, kept / 2) << "the builder keeps exactly the pairs a linear scan keeps";
  }
}

// Paints `cells` of an existing sprite with another colour (alpha kept).
RgbaBillboard RecolourCells(RgbaBillboard b, const std::vector<Cell>& cells,
                            const std::array<uint8_t, 3>& rgb) {
  for (const Cell& c : cells) {
    uint8_t* p = b.rgba.data() + (static_cast<size_t>(c.y) * 32 + c.x) * 4;
    p[0] = rgb[0];
    p[1] = rgb[1];
    p[2] = rgb[2];
  }
  return b;
}

TEST(TransitionColourBlob, FeatureOnHandMadePairs) {
  const RgbaBillboard body = Sprite(Rectangle(8, 10, 20, 32, 255));
  // 3 x 2, dR 110
  RgbaBillboard two_patches = RecolourCells(body, Rectangle(9, 12, 12, 14, 255), {90, 100, 50});
  two_patches =
      RecolourCells(two_patches, Rectangle(15, 20, 17, 21, 255), {200, 40, 20});  // 2 x 1, 90
  // dR+dG+dB 80
  const RgbaBillboard faint = RecolourCells(body, Rectangle(9, 12, 12, 14, 255), {150, 80, 40});
  RgbaBillboard half_transparent = Sprite(Rectangle(8, 10, 20, 32, 255));
  for (const Cell& c : Rectangle(9, 12, 12, 14, 0))
    half_transparent.rgba[(c.y * 32 + c.x) * 4 + 3] = 100;
  half_transparent = RecolourCells(half_transparent, Rectangle(9, 12, 12, 14, 255), {90, 100, 50});
  // not 4-connected
  const RgbaBillboard diagonal = RecolourCells(body, {{9, 12, 255}, {10, 13, 255}}, {0, 0, 0});
  const std::vector<RgbaBillboard> sprites = {body, two_patches, faint, half_transparent, diagonal};
  std::vector<SpriteInput> inputs;
  for (size_t k = 0; k < sprites.size(); ++k) {
    inputs.push_back({static_cast<int64_t>(k + 1), static_cast<int64_t>(k + 1), {}, &sprites[k]});
  }
  SpriteStore s(CellPerPixel(), 100.0);
  s.Append(inputs);
  auto blob = [&](int32_t i, int32_t j) {
    return LargestColourBlob(s.image(i), s.image(j), s.window());
  };
  EXPECT_EQ(blob(0, 1), 6);  // the larger of the two patches
  EXPECT_EQ(blob(0, 2), 0);  // below the colour step
  EXPECT_EQ(blob(0, 3), 0);  // the patch is not opaque in both
  EXPECT_EQ(blob(0, 4), 1);  // two cells touching at a corner are two blobs
  for (int32_t i = 0; i < s.size(); ++i) {
    EXPECT_EQ(blob(i, i), 0);
    for (int32_t j = 0; j < s.size(); ++j) EXPECT_EQ(blob(i, j), blob(j, i));
  }
  TransitionWeights w = LinfWeights(CellPerPixel(), 0.05, 0.5);
  w.stage2_variant = Stage2Variant::kColourBlob;
  w.colour_blob_max_velocity_mps = 0.05;
  w.colour_blob_max_cells = 4;
  const TransitionClassifier c(w);
  ASSERT_TRUE(c.colour_blob());
  double d = -1;
  EXPECT_FALSE(c.Stage2(s, 0, 1, &d));  // blob 6 > 4
  EXPECT_TRUE(c.Stage2(s, 0, 4, &d));   // blob 1, velocity 0
  EXPECT_NEAR(d, 0.25, 1e-12);
  EXPECT_TRUE(c.Stage2(s, 0, 3, &d));
  EXPECT_EQ(d, 0.0);
}

// Only the velocity filters a colour_blob pair before it is evaluated: on generated sprites
// in the 1 px window the builder keeps exactly what a linear scan keeps.
TEST(TransitionColourBlob, BuilderKeepsWhatALinearScanKeeps) {
  SyntheticSpriteOptions so;
  so.frames = 100;
  so.seed = 9;
  const auto sprites = MakeSyntheticSprites(so);
  ComparisonWindow window;
  window.width_m = 0.24;
  window.height_m = 0.18;
  window.cells_x = 60;
  window.cells_y = 45;
  window.align = HorizontalAlignment::kContactPoint;
  SpriteStore store(window, so.px_per_m);
  store.Append(AsSpriteInputs(sprites), 2);
  TransitionWeights w = LinfWeights(window, 0.05, 0.5);
  w.stage2_variant = Stage2Variant::kColourBlob;
  w.colour_blob_max_velocity_mps = 0.05;
  w.colour_blob_max_cells = 30;
  const TransitionClassifier c(w);
  int64_t kept = 0;
  for (int32_t i = 0; i < store.size(); ++i) {
    for (int32_t j = 0; j < store.size(); ++j) {
      if (i == j) continue;
      double d = -1, e = -1;
      const bool full = c.Stage2(store, i, j, &d);
      ASSERT_EQ(full, c.Stage2(store, j, i, &e));
      ASSERT_FALSE(full && c.SignatureRejects(store, i, j));
      if (full) {
        ASSERT_EQ(d, e);
        ASSERT_TRUE(c.Stage1Accepts(store.cheap(i), store.cheap(j)));
      }
      kept += full;
    }
  }
  EXPECT_GT(kept, 0);
  TransitionBuilder builder(w, so.px_per_m);
  builder.BuildFromScratch(AsSpriteInputs(sprites), BuildOptions{.threads = 2});
  EXPECT_EQ(builder.stats().kept_pairs, kept / 2);
}

std::string WeightsErrorOf(const std::string& text) {
  try {
    ParseWeights(text, "w.json");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(TransitionLinf, WeightsFileCarriesTheVariant) {
  // The shipped paper file (version 1) loads as the paper's variant and is written back as
  // version 1; so is the default (the paper's six); the colour_cells option is a version-2 file.
  EXPECT_EQ(PaperWeights().stage2_variant, Stage2Variant::kPaper);
  EXPECT_EQ(nlohmann::json::parse(WeightsToJson(PaperWeights()))["version"], 1);
  EXPECT_FALSE(TransitionClassifier(PaperWeights()).linf());
  EXPECT_EQ(DefaultWeights().stage2_variant, Stage2Variant::kPaper);
  EXPECT_EQ(nlohmann::json::parse(WeightsToJson(DefaultWeights()))["version"], 1);
  EXPECT_EQ(ColourCellsWeights().stage2_variant, Stage2Variant::kColourCells);
  EXPECT_EQ(nlohmann::json::parse(WeightsToJson(ColourCellsWeights()))["version"], 2);

  ComparisonWindow window;
  window.cells_x = 60;
  window.cells_y = 45;
  window.height_m = 0.18;
  window.align = HorizontalAlignment::kContactPoint;
  const TransitionWeights w = LinfWeights(window, 0.045, 0.55);
  const std::string text = WeightsToJson(w);
  const nlohmann::json good = nlohmann::json::parse(text);
  EXPECT_EQ(good["version"], 2);
  EXPECT_EQ(good["stage2"]["variant"], "linf");
  const TransitionWeights back = ParseWeights(text, "w.json");
  EXPECT_EQ(back.stage2_variant, Stage2Variant::kLinf);
  EXPECT_EQ(back.linf_max_velocity_mps, 0.045);
  EXPECT_EQ(back.linf_max_alpha, 0.55);
  EXPECT_EQ(back.window.cells_x, 60);
  EXPECT_EQ(WeightsToJson(back), text);
  EXPECT_EQ(TransitionClassifier(back).linf_alpha_limit(), 140);  // floor(0.55 * 255)

  auto with = [&](const std::function<void(nlohmann::json&)>& edit) {
    nlohmann::json j = good;
    edit(j);
    return WeightsErrorOf(j.dump());
  };
  EXPECT_EQ(with([](auto&) {}), "");
  EXPECT_EQ(with([](auto& j) { j["stage2"]["variant"] = "paper"; }), "");
  EXPECT_NE(with([](auto& j) { j["stage2"]["variant"] = "max"; }).find("w.json: stage2.variant:"),
            std::string::npos);
  EXPECT_NE(
      with([](auto& j) { j["stage2"].erase("variant"); }).find("w.json: stage2.variant: missing"),
      std::string::npos);
  EXPECT_NE(with([](auto& j) {
              j["stage2"]["linf"].erase("max_alpha_linf");
            }).find("w.json: stage2.linf.max_alpha_linf: missing"),
            std::string::npos);
  EXPECT_NE(with([](auto& j) {
              j["stage2"]["linf"]["max_alpha_linf"] = 1.5;
            }).find("w.json: stage2.linf.max_alpha_linf:"),
            std::string::npos);
  EXPECT_NE(with([](auto& j) {
              j["stage2"]["linf"]["max_velocity_mps"] = -0.1;
            }).find("w.json: stage2.linf.max_velocity_mps:"),
            std::string::npos);
  EXPECT_NE(with([](auto& j) {
              j["stage2"]["linf"]["max_velocity_mps"] = "fast";
            }).find("w.json: stage2.linf.max_velocity_mps:"),
            std::string::npos);
  // The colour_blob variant's fields.
  TransitionWeights b = w;
  b.stage2_variant = Stage2Variant::kColourBlob;
  b.colour_blob_max_velocity_mps = 0.05;
  b.colour_blob_max_cells = 12;
  const std::string btext = WeightsToJson(b);
  const TransitionWeights bback = ParseWeights(btext, "w.json");
  EXPECT_EQ(bback.stage2_variant, Stage2Variant::kColourBlob);
  EXPECT_EQ(bback.colour_blob_max_cells, 12);
  EXPECT_EQ(bback.colour_blob_max_velocity_mps, 0.05);
  EXPECT_EQ(WeightsToJson(bback), btext);
  const nlohmann::json bgood = nlohmann::json::parse(btext);
  auto bwith = [&](const std::function<void(nlohmann::json&)>& edit) {
    nlohmann::json j = bgood;
    edit(j);
    return WeightsErrorOf(j.dump());
  };
  EXPECT_NE(bwith([](auto& j) {
              j["stage2"]["colour_blob"]["max_blob_cells"] = -1;
            }).find("w.json: stage2.colour_blob.max_blob_cells:"),
            std::string::npos);
  EXPECT_NE(bwith([](auto& j) {
              j["stage2"]["colour_blob"]["max_blob_cells"] = 2.5;
            }).find("w.json: stage2.colour_blob.max_blob_cells:"),
            std::string::npos);
  EXPECT_NE(bwith([](auto& j) {
              j["stage2"]["colour_blob"].erase("max_velocity_mps");
            }).find("w.json: stage2.colour_blob.max_velocity_mps: missing"),
            std::string::npos);
  // A version-1 file has no variant: one that names one is refused rather than misread.
  EXPECT_NE(with([](auto& j) { j["version"] = 1; }).find("w.json: stage2.variant:"),
            std::string::npos);
}

}  // namespace
}  // namespace ss
