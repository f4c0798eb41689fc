#pragma once
// The in-memory sprite the transition finder works on: a perspective-corrected
// billboard (RGBA at the bank's fixed px_per_m, aligned on its ground contact
// pixel) and the four cheap per-sprite features of seed 000 §3.
// Definitions: docs/transitions.md.
#include <cstddef>
#include <cstdint>
#include <vector>

namespace ss {

// A billboard as the bank stores it: straight (not premultiplied) colour + alpha, 4 bytes
// a pixel, row-major, top row first, at the bank's px_per_m. The anchor is the ground
// contact point in pixel-centre coordinates (pixel (x, y) has its centre at (x, y)), as
// the rectifier and the bank store it; it may be fractional. Every feature is symmetric
// in the three colour channels, so RGBA and the bank's BGRA give the same features
// (only the names of CheapFeatures::colour[] change).
struct RgbaBillboard {
  int width = 0;
  int height = 0;
  double anchor_x_px = 0;
  double anchor_y_px = 0;
  std::vector<uint8_t> rgba;  // width * height * 4 bytes: R, G, B, A (or B, G, R, A)
  // A floor sprite (seen from above, facing the image's top; the anchor its centre) rather than
  // an upright billboard (the anchor its contact point at the bottom): the comparison window is
  // centred on it and turned to its length (comparison.h).
  bool floor = false;

  const uint8_t* Pixel(int x, int y) const {
    return rgba.data() + (static_cast<size_t>(y) * width + x) * 4;
  }
};

// The four cheap features of one sprite (precomputed once, compared many times).
struct CheapFeatures {
  double velocity_x_mps = 0;  // ground velocity, from the clip neighbours (pipeline)
  double velocity_y_mps = 0;
  double colour[3] = {0, 0, 0};  // alpha-weighted mean R, G, B of the billboard, 0..255
  double area_m2 = 0;            // alpha area: sum(alpha / 255) / px_per_m^2
  double eccentricity = 0;       // sqrt(1 - l2 / l1) of the alpha second moments, 0..1
};

// Mean colour, area and eccentricity of a billboard (velocity is not a pixel property
// and is left 0). Throws InputError("billboard", reason) for a malformed billboard.
CheapFeatures DescribeBillboard(const RgbaBillboard& billboard, double px_per_m);

// Throws InputError("billboard", reason) unless sizes, anchor and byte count agree.
void ValidateBillboard(const RgbaBillboard& billboard);

// The horizontally mirrored billboard (anchor mirrored with it).
RgbaBillboard MirrorBillboard(const RgbaBillboard& billboard);

}  // namespace ss
