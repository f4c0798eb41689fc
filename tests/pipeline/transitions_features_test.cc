// Per-sprite cheap features and the stage-2 pixel features on hand-made billboards.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "core/error.h"
#include "pipeline/transitions/billboard.h"
#include "pipeline/transitions/comparison.h"
#include "pipeline/transitions/features.h"
#include "pipeline/transitions/sprite_store.h"
#include "pipeline/transitions/synthetic.h"

namespace ss {
namespace {

// A billboard of `w` x `h` transparent pixels with its anchor at (ax, ay) (pixel centres).
RgbaBillboard Blank(int w, int h, double ax, double ay) {
  RgbaBillboard b;
  b.width = w;
  b.height = h;
  b.anchor_x_px = ax;
  b.anchor_y_px = ay;
  b.rgba.assign(static_cast<size_t>(w) * h * 4, 0);
  return b;
}

void Paint(RgbaBillboard& b, int x, int y, uint8_t r, uint8_t g, uint8_t bl, uint8_t a) {
  uint8_t* p = b.rgba.data() + (static_cast<size_t>(y) * b.width + x) * 4;
  p[0] = r;
  p[1] = g;
  p[2] = bl;
  p[3] = a;
}

TEST(TransitionFeatures, DescribeRectangle) {
  // 4 x 2 opaque pixels at 100 px/m: area 8 px^2 = 8e-4 m^2; variances 15/12 and 3/12.
  RgbaBillboard b = Blank(6, 4, 2, 3);
  for (int y = 1; y <= 2; ++y)
    for (int x = 1; x <= 4; ++x) Paint(b, x, y, 10, 20, 30, 255);
  const CheapFeatures f = DescribeBillboard(b, 100.0);
  EXPECT_NEAR(f.area_m2, 8e-4, 1e-15);
  EXPECT_DOUBLE_EQ(f.colour[0], 10);
  EXPECT_DOUBLE_EQ(f.colour[1], 20);
  EXPECT_DOUBLE_EQ(f.colour[2], 30);
  EXPECT_NEAR(f.eccentricity, std::sqrt(1.0 - 0.25 / 1.25), 1e-12);
  EXPECT_EQ(f.velocity_x_mps, 0);
}

TEST(TransitionFeatures, MeanColourIsAlphaWeighted) {
  RgbaBillboard b = Blank(2, 1, 0, 0);
  Paint(b, 0, 0, 200, 0, 0, 255);
  Paint(b, 1, 0, 0, 200, 0, 51);  // alpha 0.2
  const CheapFeatures f = DescribeBillboard(b, 10.0);
  EXPECT_NEAR(f.colour[0], 200.0 / 1.2, 1e-9);
  EXPECT_NEAR(f.colour[1], 200.0 * 0.2 / 1.2, 1e-9);
  EXPECT_NEAR(f.area_m2, 1.2 / 100.0, 1e-12);
}

TEST(TransitionFeatures, CircleHasZeroEccentricityAndMirrorKeepsFeatures) {
  RgbaBillboard b = Blank(21, 21, 10, 20);
  for (int y = 0; y < 21; ++y)
    for (int x = 0; x < 21; ++x)
      if ((x - 10) * (x - 10) + (y - 10) * (y - 10) <= 81) Paint(b, x, y, x * 10, y * 10, 50, 255);
  const CheapFeatures f = DescribeBillboard(b, 100.0);
  EXPECT_LT(f.eccentricity, 1e-6);
  const CheapFeatures m = DescribeBillboard(MirrorBillboard(b), 100.0);
  EXPECT_NEAR(m.area_m2, f.area_m2, 1e-15);
  EXPECT_NEAR(m.eccentricity, f.eccentricity, 1e-9);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(m.colour[c], f.colour[c], 1e-9);
}

TEST(TransitionFeatures, MalformedBillboardIsAnInputError) {
  RgbaBillboard b = Blank(4, 4, 1, 1);
  b.rgba.pop_back();
  EXPECT_THROW(DescribeBillboard(b, 100), InputError);
  RgbaBillboard c = Blank(4, 4, 3.6, 1);  // anchor outside (pixel 3 ends at 3.5)
  try {
    DescribeBillboard(c, 100);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("anchor"), std::string::npos);
  }
}

// Window 5 x 4 px at 100 px/m with one cell per pixel. The contact point is the middle of
// the window's bottom edge, the anchor + 0.5 in pixel-edge coordinates: the anchor (2, 3.5)
// puts the window [0, 5) x [0, 4) exactly on the billboard, so every cell is one pixel.
ComparisonWindow PixelWindow() {
  ComparisonWindow w;
  w.width_m = 0.05;
  w.height_m = 0.04;
  w.cells_x = 5;
  w.cells_y = 4;
  w.align = HorizontalAlignment::kContactPoint;
  return w;
}

TEST(TransitionFeatures, ComparisonImageAlignedOnAnchor) {
  const ComparisonWindow w = PixelWindow();
  RgbaBillboard b = Blank(5, 4, 2, 3.5);
  Paint(b, 1, 1, 10, 20, 30, 255);
  Paint(b, 3, 2, 40, 50, 60, 100);
  std::vector<uint8_t> image(w.ImageBytes(), 0xAB);
  const CellBox box = MakeComparisonImage(b, 100.0, w, image.data());
  const int s = w.PlaneStride();
  EXPECT_EQ(image[1 * 5 + 1], 255);
  EXPECT_EQ(image[s + 1 * 5 + 1], 10);
  EXPECT_EQ(image[2 * s + 1 * 5 + 1], 20);
  EXPECT_EQ(image[3 * s + 1 * 5 + 1], 30);
  EXPECT_EQ(image[2 * 5 + 3], 100);
  EXPECT_EQ(image[s + 2 * 5 + 3], 40);
  int nonzero = 0;
  for (int k = 0; k < s; ++k) nonzero += image[k] != 0;
  EXPECT_EQ(nonzero, 2);
  for (int k = w.Cells(); k < s; ++k) EXPECT_EQ(image[3 * s + k], 0) << "padding must be zero";
  EXPECT_EQ(box.x0, 1);
  EXPECT_EQ(box.x1, 4);
  EXPECT_EQ(box.y0, 1);
  EXPECT_EQ(box.y1, 3);

  // The same sprite drawn further left in a wider billboard, with the anchor moved along:
  // the comparison image does not change.
  RgbaBillboard shifted = Blank(9, 6, 5, 4.5);
  Paint(shifted, 4, 2, 10, 20, 30, 255);
  Paint(shifted, 6, 3, 40, 50, 60, 100);
  std::vector<uint8_t> image2(w.ImageBytes());
  MakeComparisonImage(shifted, 100.0, w, image2.data());
  EXPECT_EQ(image, image2);
}

// A floor sprite (issue 38) faces the image's top with its anchor at its centre: its window is
// turned a quarter (width_m along the image's height) and centred on the anchor, so the tail
// below the anchor is compared too.
TEST(TransitionFeatures, AFloorSpritesWindowIsCentredAndTurnedToItsLength) {
  const ComparisonWindow w = PixelWindow();  // 5 x 4 cells over 0.05 x 0.04 m: turned, 4 x 5 px
  RgbaBillboard b = Blank(4, 5, 1.5, 2);     // anchor at the centre: the window is [0, 4) x [0, 5)
  b.floor = true;
  Paint(b, 0, 0, 10, 20, 30, 255);  // the nose's corner, top left
  Paint(b, 3, 4, 40, 50, 60, 255);  // the tail's corner, bottom right
  std::vector<uint8_t> image(w.ImageBytes(), 0);
  MakeComparisonImage(b, 100.0, w, image.data());
  // Cells are 0.04 / 5 = 0.8 px wide and 0.05 / 4 = 1.25 px tall: each corner pixel lands in its
  // corner cell, partly.
  const int s = w.PlaneStride();
  EXPECT_GT(image[0], 0);
  EXPECT_EQ(image[s + 0], 10);
  EXPECT_GT(image[3 * 5 + 4], 0) << "the tail, below the anchor";
  EXPECT_EQ(image[s + 3 * 5 + 4], 40);
  // As an upright billboard, the window's bottom would sit at the anchor: no tail.
  b.floor = false;
  MakeComparisonImage(b, 100.0, w, image.data());
  int tail = 0;
  for (int k = 0; k < w.Cells(); ++k) tail += image[s + k] == 40;
  EXPECT_EQ(tail, 0);
}

TEST(TransitionFeatures, ComparisonImageAveragesAreas) {
  // One cell covering 2 x 2 pixels: two opaque (red, blue) and two transparent.
  ComparisonWindow w;
  w.width_m = 0.02;
  w.height_m = 0.02;
  w.cells_x = 1;
  w.cells_y = 1;
  w.align = HorizontalAlignment::kContactPoint;
  RgbaBillboard b = Blank(2, 2, 0, 1.5);  // the window spans x in [-0.5, 1.5), y in [0, 2)
  Paint(b, 0, 0, 200, 0, 0, 255);
  Paint(b, 0, 1, 0, 0, 200, 255);
  std::vector<uint8_t> image(w.ImageBytes());
  MakeComparisonImage(b, 100.0, w, image.data());
  const int s = w.PlaneStride();
  // The cell is 2 x 2 px = 4 px^2 and holds column 0 entirely: 2 opaque px^2.
  EXPECT_EQ(image[0], 128);  // 255 * 2 / 4 = 127.5
  EXPECT_EQ(image[s], 100);  // alpha-weighted mean of red 200 and 0
  EXPECT_EQ(image[3 * s], 100);
}

TEST(TransitionFeatures, CentroidAlignmentIgnoresTheContactColumn) {
  // Centred on the alpha centroid, the same shape gives the same comparison image
  // wherever its contact point is; centred on the contact point it does not.
  ComparisonWindow w = PixelWindow();
  w.align = HorizontalAlignment::kAlphaCentroid;
  RgbaBillboard a = Blank(7, 4, 1, 3.5), b = Blank(7, 4, 5, 3.5);
  for (RgbaBillboard* bb : {&a, &b}) {
    for (int x = 2; x <= 4; ++x) Paint(*bb, x, 2, 90, 80, 70, 255);  // centroid at x = 3.5 (edges)
    Paint(*bb, 3, 3, 90, 80, 70, 255);
  }
  std::vector<uint8_t> ia(w.ImageBytes()), ib(w.ImageBytes());
  MakeComparisonImage(a, 100.0, w, ia.data());
  MakeComparisonImage(b, 100.0, w, ib.data());
  EXPECT_EQ(ia, ib);
  EXPECT_EQ(ia[2 * 5 + 1], 255);  // window [1, 6): pixel 2 is cell 1
  w.align = HorizontalAlignment::kContactPoint;
  MakeComparisonImage(a, 100.0, w, ia.data());
  MakeComparisonImage(b, 100.0, w, ib.data());
  EXPECT_NE(ia, ib);
}

TEST(TransitionFeatures, PixelDifferencesOnHandMadePair) {
  const ComparisonWindow w = PixelWindow();
  RgbaBillboard a = Blank(5, 4, 2, 3.5), b = Blank(5, 4, 2, 3.5);
  for (int y = 0; y < 4; ++y) {
    for (int x = 0; x < 3; ++x) Paint(a, x, y, 100, 100, 100, 255);
    for (int x = 1; x < 4; ++x) Paint(b, x, y, 110, 90, 100, 255);
  }
  SpriteStore store(w, 100.0);
  std::vector<SpriteInput> in = {{1, 1, DescribeBillboard(a, 100), &a},
                                 {2, 2, DescribeBillboard(b, 100), &b}};
  store.Append(in);
  // Union window: columns 0..3 x 4 rows = 16 cells; alpha differs on columns 0 and 3 (8 cells).
  const PixelDifference d = store.Pixels(0, 1);
  EXPECT_DOUBLE_EQ(d.alpha, 0.5);
  // Overlap: columns 1, 2 with weight 255 each and L1 colour distance 20.
  EXPECT_DOUBLE_EQ(d.colour, 20.0 / 3.0);
  const PixelDifference e = store.Pixels(1, 0);
  EXPECT_DOUBLE_EQ(e.alpha, d.alpha);
  EXPECT_DOUBLE_EQ(e.colour, d.colour);
  const PixelDifference self = store.Pixels(0, 0);
  EXPECT_EQ(self.alpha, 0);
  EXPECT_EQ(self.colour, 0);

  // No overlap at all: the colour difference is the maximum, 255.
  RgbaBillboard c = Blank(5, 4, 2, 3.5);
  Paint(c, 4, 0, 1, 2, 3, 255);
  store.Append(std::vector<SpriteInput>{{3, 3, DescribeBillboard(c, 100), &c}});
  EXPECT_EQ(store.Pixels(0, 2).colour, 255.0);
  EXPECT_DOUBLE_EQ(store.Pixels(0, 2).alpha, 13.0 / 20.0);  // union: all 5 x 4 cells, 12 + 1 differ
}

TEST(TransitionFeatures, CheapDifferencesAreSymmetric) {
  CheapFeatures a, b;
  a.velocity_x_mps = 0.1;
  a.velocity_y_mps = -0.2;
  b.velocity_x_mps = -0.2;
  b.velocity_y_mps = 0.2;
  a.colour[0] = 100, a.colour[1] = 50, a.colour[2] = 10;
  b.colour[0] = 90, b.colour[1] = 70, b.colour[2] = 10;
  a.area_m2 = 0.004, b.area_m2 = 0.005;
  a.eccentricity = 0.9, b.eccentricity = 0.6;
  const CheapDifference d = CheapDiff(a, b);
  EXPECT_DOUBLE_EQ(d[0], 0.5);  // |(0.3, -0.4)|
  EXPECT_DOUBLE_EQ(d[1], 30.0);
  EXPECT_NEAR(d[2], 0.001, 1e-15);
  EXPECT_NEAR(d[3], 0.3, 1e-15);
  EXPECT_EQ(CheapDiff(b, a), d);
  EXPECT_EQ(CheapDiff(a, a), (CheapDifference{0, 0, 0, 0}));
}

TEST(TransitionFeatures, SixFeaturesSymmetricOnSyntheticSprites) {
  SyntheticSpriteOptions o;
  o.frames = 60;
  const auto sprites = MakeSyntheticSprites(o);
  SpriteStore store(ComparisonWindow{}, o.px_per_m);
  store.Append(AsSpriteInputs(sprites));
  for (int32_t i = 0; i < store.size(); i += 7) {
    for (int32_t j = 0; j < store.size(); j += 5) {
      EXPECT_EQ(store.Features(i, j), store.Features(j, i));
    }
    const PairFeatures self = store.Features(i, i);
    for (double v : self) EXPECT_EQ(v, 0.0);
  }
}

TEST(TransitionFeatures, SimdKernelEqualsScalar) {
  std::mt19937 rng(7);
  for (const auto& [cx, cy] :
       {std::pair{32, 32}, std::pair{5, 4}, std::pair{64, 64}, std::pair{17, 9}}) {
    ComparisonWindow w;
    w.cells_x = cx;
    w.cells_y = cy;
    const int s = w.PlaneStride();
    std::vector<uint8_t> a(w.ImageBytes(), 0), b(w.ImageBytes(), 0);
    for (int trial = 0; trial < 3; ++trial) {
      for (int p = 0; p < 4; ++p) {
        for (int k = 0; k < w.Cells(); ++k) {
          a[p * s + k] = trial == 2 ? 255 : rng() % 256;
          b[p * s + k] = trial == 2 ? (p == 0 ? 255 : 0) : rng() % 256;
        }
      }
      const PixelSums fast = SumPixelDifferences(a.data(), b.data(), s);
      const PixelSums slow = SumPixelDifferencesScalar(a.data(), b.data(), s);
      EXPECT_EQ(fast.alpha_abs_diff, slow.alpha_abs_diff);
      EXPECT_EQ(fast.weight, slow.weight);
      EXPECT_EQ(fast.weighted_colour, slow.weighted_colour)
          << cx << "x" << cy << " trial " << trial;
    }
  }
}

TEST(TransitionFeatures, WindowValidation) {
  ComparisonWindow w;
  std::string why;
  EXPECT_TRUE(w.IsValid(&why));
  w.cells_x = 129;
  EXPECT_FALSE(w.IsValid(&why));
  EXPECT_NE(why.find("4096"), std::string::npos);
  w.cells_x = 32;
  w.width_m = 0;
  EXPECT_FALSE(w.IsValid(&why));
  EXPECT_NE(why.find("width_m"), std::string::npos);
}

}  // namespace
}  // namespace ss
