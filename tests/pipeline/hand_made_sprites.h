#pragma once
// Hand-made billboards for the transitions tests: a 32 x 32 px billboard at 100 px/m, anchored
// at (15.5, 31.5), compared in a 32 x 32 cell window, so that cell (u, v) is exactly pixel
// (u, v) and cell alphas are the painted alphas.
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "pipeline/transitions/builder.h"
#include "pipeline/transitions/sprite_store.h"

namespace ss::testing {

inline ComparisonWindow CellPerPixel() {
  ComparisonWindow w;
  w.width_m = 0.32;
  w.height_m = 0.32;
  w.cells_x = 32;
  w.cells_y = 32;
  w.align = HorizontalAlignment::kContactPoint;
  return w;
}

struct Cell {
  int x, y;
  uint8_t alpha;
};

// The painted cells in one colour; the rest transparent.
inline RgbaBillboard Sprite(const std::vector<Cell>& cells,
                            const std::array<uint8_t, 3>& rgb = {200, 100, 50}) {
  RgbaBillboard b;
  b.width = 32;
  b.height = 32;
  b.anchor_x_px = 15.5;
  b.anchor_y_px = 31.5;
  b.rgba.assign(32 * 32 * 4, 0);
  for (const Cell& c : cells) {
    uint8_t* p = b.rgba.data() + (static_cast<size_t>(c.y) * 32 + c.x) * 4;
    p[0] = rgb[0];
    p[1] = rgb[1];
    p[2] = rgb[2];
    p[3] = c.alpha;
  }
  return b;
}

// Cells [x0, x1) x [y0, y1) at one alpha.
inline std::vector<Cell> Rectangle(int x0, int y0, int x1, int y1, uint8_t alpha) {
  std::vector<Cell> out;
  for (int y = y0; y < y1; ++y) {
    for (int x = x0; x < x1; ++x) out.push_back({x, y, alpha});
  }
  return out;
}

}  // namespace ss::testing
