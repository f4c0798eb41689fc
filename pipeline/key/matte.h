#pragma once
// What a keyer makes of one frame. The layers are full-frame images, but the
// keyers only compute them inside `regions` (the boxes their coarse pass found);
// alpha and shadow are zero everywhere else, colour is undefined there.
// A Matte is meant to be reused frame after frame: its buffers keep their
// allocation and only the previous frame's regions are cleared.
#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

namespace ss {

// The coarse pass's view of a frame: one cell per `step` x `step` pixels,
// sampled at the cell centre.
struct CoarseGrid {
  int step = 0;                     // cell size, pixels
  int cols = 0, rows = 0;           // cells across and down
  std::vector<uint8_t> foreground;  // cols*rows, 1 where the sample is not background
  std::vector<uint8_t> shade;       // cols*rows, 1 where the sample is darkened background
  std::vector<int32_t> label;       // cols*rows, component id (1..) of each region cell, 0 none
  std::vector<int32_t> queue;       // scratch for the labelling
  std::vector<uint8_t> dilated;     // scratch: foreground dilated by one cell
};

// One connected part of the coarse grid: the box where the fine pass ran.
struct KeyRegion {
  int id = 0;      // its label in CoarseGrid::label
  cv::Rect box;    // pixels, cell box + margin, clipped to the frame
  cv::Rect cells;  // the region's cells (coarse grid coordinates)
  int foreground_cells = 0;
  bool overlaps_other = false;  // its box intersects another region's box
};

// One pixel's key, as the keyers' per-pixel functions return it.
struct PixelKey {
  int alpha;   // 0..255
  int shadow;  // 0..255
};

struct Matte {
  cv::Mat alpha;   // CV_8U, 255 = subject, 0 = background
  cv::Mat shadow;  // CV_8U, floor darkening relative to the empty enclosure (255 = black), outside
                   // the subject
  cv::Mat colour;  // CV_8UC3, the frame's colour with spill removed; valid inside regions only
  std::vector<KeyRegion> regions;  // where the fine pass ran this frame
  CoarseGrid coarse;
};

}  // namespace ss
