#pragma once
// Stage-2 pixel features. Every billboard is resampled once into a fixed metric
// comparison window aligned on its ground contact point (a "comparison image":
// planar uint8 A, R, G, B), so that comparing two sprites is one pass over a few
// contiguous kilobytes. Definitions: docs/transitions.md.
#include <cstdint>
#include <string>

#include "pipeline/transitions/billboard.h"

namespace ss {

// How the window is placed horizontally on a billboard. Vertically it always stands on
// the floor (its bottom edge at the contact point's height).
enum class HorizontalAlignment {
  kAlphaCentroid,  // centred on the alpha-weighted mean column (stable while feet move)
  kContactPoint,   // centred on the contact point (the lowest sprite point, seed 000 §2.1)
};

// The metric window every billboard is resampled into: width_m wide, height_m tall,
// standing on the ground; cells_x * cells_y cells.
struct ComparisonWindow {
  double width_m = 0.24;
  double height_m = 0.16;
  int cells_x = 32;
  int cells_y = 32;
  HorizontalAlignment align = HorizontalAlignment::kAlphaCentroid;

  int Cells() const { return cells_x * cells_y; }
  // Bytes of one plane: Cells() rounded up to a multiple of 64 (zero padded).
  int PlaneStride() const { return (Cells() + 63) / 64 * 64; }
  // Bytes of one comparison image (four planes).
  int ImageBytes() const { return 4 * PlaneStride(); }
  // False with "FIELD: reason" lines in `why` (core/option_checks.h) for non-positive sizes or
  // more than 4096 cells.
  bool IsValid(std::string* why) const;
};

// The cells holding non-zero alpha: [x0, x1) x [y0, y1); empty when x0 >= x1.
struct CellBox {
  int16_t x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  bool empty() const { return x0 >= x1 || y0 >= y1; }
};

// The smallest box containing both (the "union window").
CellBox UnionBox(const CellBox& a, const CellBox& b);
inline int BoxArea(const CellBox& b) { return b.empty() ? 0 : (b.x1 - b.x0) * (b.y1 - b.y0); }

// Resamples `billboard` (at px_per_m) into the window by exact area averaging:
// cell alpha = mean alpha over the cell, cell colour = alpha-weighted mean colour.
// Writes window.ImageBytes() bytes at `image` (planes A, R, G, B; padding zeroed);
// returns the box of non-zero alpha cells.
CellBox MakeComparisonImage(const RgbaBillboard& billboard, double px_per_m,
                            const ComparisonWindow& window, uint8_t* image);

// The two stage-2 pixel features of a sprite pair.
struct PixelDifference {
  double alpha = 0;   // sum |A_i - A_j| / (255 * cells of the union window), 0..1
  double colour = 0;  // sum min(A_i,A_j) * L1(RGB_i - RGB_j) / (3 * sum min(A_i,A_j)), 0..255
};

// Integer sums behind PixelDifference over whole planes (padding contributes 0).
struct PixelSums {
  uint64_t alpha_abs_diff = 0;   // sum |A_i - A_j|
  uint64_t weight = 0;           // sum min(A_i, A_j)
  uint64_t weighted_colour = 0;  // sum min(A_i, A_j) * (|dR| + |dG| + |dB|)
};

// SIMD (AVX2 when the CPU has it, else SSE2). `stride` = window.PlaneStride().
PixelSums SumPixelDifferences(const uint8_t* image_a, const uint8_t* image_b, int stride);
// sum |A_i - A_j| over the alpha plane alone (= PixelSums::alpha_abs_diff), for an early
// exit of stage 2 before the colour planes are read.
uint64_t SumAlphaDifference(const uint8_t* image_a, const uint8_t* image_b, int stride);
// max |A_i - A_j| over the alpha plane (0..255): the linf stage 2's pixel feature times 255.
int MaxAlphaDifference(const uint8_t* image_a, const uint8_t* image_b, int stride);
// The colour_blob stage 2's pixel feature: the most cells in one 4-connected blob of cells
// opaque in both (A >= 128) whose colours differ by |dR| + |dG| + |dB| >= 90. Symmetric.
int LargestColourBlob(const uint8_t* image_a, const uint8_t* image_b,
                      const ComparisonWindow& window);
// The colour_cells stage 2's pixel feature: how many cells are opaque in both (A >= 128) and
// differ in colour by |dR| + |dG| + |dB| >= 90 (kColourStep). Symmetric; padding counts 0.
// SSE2; ColourCellCountScalar is the plain loop it is tested against.
inline constexpr int kColourStep = 90;
inline constexpr int kOpaqueAlpha = 128;
int ColourCellCount(const uint8_t* image_a, const uint8_t* image_b, int stride);
int ColourCellCountScalar(const uint8_t* image_a, const uint8_t* image_b, int stride);
// Plain loop, the reference the SIMD kernels are tested against.
PixelSums SumPixelDifferencesScalar(const uint8_t* image_a, const uint8_t* image_b, int stride);
// The features from the sums and the two alpha boxes.
PixelDifference PixelDifferenceFromSums(const PixelSums& sums, const CellBox& box_a,
                                        const CellBox& box_b);

}  // namespace ss
