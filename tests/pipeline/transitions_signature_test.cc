// The silhouette signature: its alpha bounds are true lower bounds of the alpha plane's
// difference (hand-made sprites), and the filter built on them never rejects a pair that
// full stage 2 accepts (generated sprites).
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "pipeline/transitions/builder.h"
#include "pipeline/transitions/classifier.h"
#include "pipeline/transitions/sprite_store.h"
#include "pipeline/transitions/synthetic.h"
#include "tests/pipeline/hand_made_sprites.h"

namespace ss {
namespace {

using testing::Cell;
using testing::CellPerPixel;
using testing::Rectangle;
using testing::Sprite;

SpriteStore StoreOf(const std::vector<RgbaBillboard>& billboards) {
  SpriteStore store(CellPerPixel(), 100.0);
  std::vector<SpriteInput> inputs;
  for (size_t k = 0; k < billboards.size(); ++k) {
    inputs.push_back(
        {static_cast<int64_t>(k + 1), static_cast<int64_t>(k + 1), {}, &billboards[k]});
  }
  store.Append(inputs);
  return store;
}

uint64_t Exact(const SpriteStore& s, int32_t i, int32_t j) {
  return SumAlphaDifference(s.image(i), s.image(j), s.window().PlaneStride());
}

TEST(TransitionSignature, BoundsOnHandMadeSprites) {
  const std::vector<RgbaBillboard> sprites = {
      Sprite(Rectangle(8, 10, 20, 32, 255)),   // 0: body
      Sprite(Rectangle(10, 14, 18, 30, 255)),  // 1: inside 0
      Sprite(Rectangle(10, 10, 14, 32, 255)),  // 2: a bar ...
      Sprite({{0, 0, 255}, {1, 1, 255}}),      // 3: a diagonal pair ...
      Sprite({{1, 0, 255}, {0, 1, 255}}),      // 4: ... and the other diagonal
      Sprite(Rectangle(0, 0, 32, 32, 255)),    // 5: everything
      Sprite({{3, 3, 100}, {30, 29, 7}, {16, 16, 255}, {17, 16, 1}}),  // 6: scattered alphas
      Sprite(Rectangle(8, 10, 12, 32, 255)),  // 7: ... and it 2 cells to the left
  };
  const SpriteStore s = StoreOf(sprites);
  // The images hold the painted alphas, so the exact difference is known by hand.
  EXPECT_EQ(Exact(s, 0, 1), (12 * 22 - 8 * 16) * 255u);
  EXPECT_EQ(Exact(s, 3, 4), 4 * 255u);

  // Nested silhouettes: every cell differs with the same sign, so every partition's bound is exact.
  EXPECT_EQ(s.CoarseAlphaBound(0, 1), Exact(s, 0, 1));
  EXPECT_EQ(s.SignatureAlphaBound(0, 1), Exact(s, 0, 1));
  EXPECT_EQ(s.SignatureAlphaBound(5, 6), Exact(s, 5, 6));
  // The diagonal swap has the same sums in every block, row and column: the bound is 0.
  EXPECT_EQ(s.SignatureAlphaBound(3, 4), 0u);
  // A bar moved by 2 cells inside one 8-cell-wide block of the 4 x 4 grid: that grid sees
  // nothing, the one-cell column bands see all of it.
  EXPECT_EQ(Exact(s, 2, 7), 4 * 22 * 255u);
  EXPECT_EQ(s.CoarseAlphaBound(2, 7), 0u);
  EXPECT_EQ(s.SignatureAlphaBound(2, 7), Exact(s, 2, 7));

  for (int32_t i = 0; i < s.size(); ++i) {
    EXPECT_EQ(s.SignatureAlphaBound(i, i), 0u);
    for (int32_t j = 0; j < s.size(); ++j) {
      EXPECT_EQ(s.SignatureAlphaBound(i, j), s.SignatureAlphaBound(j, i));
      EXPECT_LE(s.CoarseAlphaBound(i, j), s.SignatureAlphaBound(i, j)) << i << " " << j;
      EXPECT_LE(s.SignatureAlphaBound(i, j), Exact(s, i, j)) << i << " " << j;
    }
  }
}

TEST(TransitionSignature, BoundsOnRandomSprites) {
  std::mt19937 rng(12);
  std::vector<RgbaBillboard> sprites;
  for (int k = 0; k < 40; ++k) {
    std::vector<Cell> cells;
    const int blobs = 1 + static_cast<int>(rng() % 4);
    for (int b = 0; b < blobs; ++b) {
      const int x0 = rng() % 28, y0 = rng() % 28;
      for (const Cell& c : Rectangle(x0, y0, x0 + 1 + rng() % 4, y0 + 1 + rng() % 4, rng() % 256))
        cells.push_back(c);
    }
    sprites.push_back(Sprite(cells));
  }
  const SpriteStore s = StoreOf(sprites);
  int strictly_below = 0;
  for (int32_t i = 0; i < s.size(); ++i) {
    for (int32_t j = 0; j < s.size(); ++j) {
      ASSERT_LE(s.CoarseAlphaBound(i, j), s.SignatureAlphaBound(i, j));
      ASSERT_LE(s.SignatureAlphaBound(i, j), Exact(s, i, j));
      strictly_below += s.SignatureAlphaBound(i, j) < Exact(s, i, j);
    }
  }
  EXPECT_GT(strictly_below, 0) << "the sprites must exercise a bound below the exact value";
}

// Over every pair of a generated set, at a tight, the shipped and a loose stage-2
// threshold: a pair the signature rejects is one full stage 2 rejects, the filter rejects
// most pairs, and the builder's counts add up.
TEST(TransitionSignature, NeverRejectsAPairStageTwoAccepts) {
  SyntheticSpriteOptions so;
  so.frames = 300;
  so.seed = 6;
  const auto sprites = MakeSyntheticSprites(so);
  SpriteStore store(ComparisonWindow{}, so.px_per_m);
  store.Append(AsSpriteInputs(sprites), 2);
  const TransitionWeights& shipped = PaperWeights();
  for (const double shift : {1.5, 0.0, -3.0}) {
    TransitionWeights w = shipped;
    w.stage2_bias += shift;
    const TransitionClassifier c(w);
    int64_t accepted = 0, rejected = 0, signature_rejected = 0;
    for (int32_t i = 0; i < store.size(); ++i) {
      for (int32_t j = 0; j < store.size(); ++j) {
        if (i == j) continue;
        const bool full = c.Stage2Accepts(c.Distance(store.Features(i, j)));
        const bool excluded = c.SignatureRejects(store, i, j);
        ASSERT_FALSE(excluded && full) << "pair " << i << " " << j << " shift " << shift;
        ASSERT_EQ(excluded, c.SignatureRejects(store, j, i));
        (full ? accepted : rejected) += 1;
        signature_rejected += excluded;
      }
    }
    EXPECT_GT(accepted, 0) << "shift " << shift
                           << ": some pairs must be accepted for the test to mean anything";
    EXPECT_GT(signature_rejected, rejected / 2) << "shift " << shift;

    TransitionBuilder builder(w, so.px_per_m);
    builder.BuildFromScratch(AsSpriteInputs(sprites), BuildOptions{.threads = 2});
    const BuildStats& st = builder.stats();
    EXPECT_EQ(st.stage1_candidates, st.signature_rejected + st.stage2_evaluations);
    EXPECT_LT(st.stage2_evaluations, st.stage1_candidates);
    EXPECT_GE(st.stage2_evaluations, st.kept_pairs);
  }
}

}  // namespace
}  // namespace ss
