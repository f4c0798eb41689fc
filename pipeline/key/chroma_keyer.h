#pragma once
// Green-screen keyer by colour difference (docs/keying.md). For a pixel with
// luma Y = (B + 2G + R) / 4 the key is k = (G - max(R, B)) / Y: it does not
// change when the floor is merely darker (vignetting, a shadow). Training on
// the empty enclosure learns, per coarse cell, the green's luma Y_bg, its key
// k_bg and the key's noise; a pixel is background above
// k_hi = k_bg - max(min_margin * k_bg, noise_z * sigma_k), and alpha ramps up
// to 1 over ramp * k_bg below that. Despill limits G to a blend of max(R, B)
// and min(R, B) (`despill_bias`; 0.5: their mean). The shadow layer is the
// floor's darkening 1 - Y / Y_bg outside the subject. Pixels of the empty
// enclosure that the model itself keys (not green: the room behind a wall)
// are never keyed.
#include <cstdint>
#include <vector>

#include "pipeline/key/keyer.h"
#include "pipeline/key/shared_options.h"

namespace ss {

struct KeyingConfig;

struct ChromaKeyerOptions {
  GridOptions grid;
  double noise_z = 5.0;         // background tolerance in noise std of the learned key...
  double min_margin = 0.2;      // ...and at least this fraction of the learned key
  double ramp = 0.6;            // alpha goes 0 -> 1 over this fraction of the learned key
  double coarse_alpha = 0.25;   // a sample with a larger alpha marks its cell as foreground
  double coarse_shadow = 0.12;  // a sample darkened more marks its cell as shaded
  double min_key = 0.1;  // training cells with a smaller key k_bg are not green and never keyed
  double max_unkeyable = 0.9;  // training fails when more than this fraction of cells is not green
  // The contact shadow: luma below (1 - max_darkening) of the floor's is subject, not shadow.
  ShadowOptions shadow;
  DespillOptions despill;  // the green cast removed from the subject's colour
  // When both are >= 0 (the station config's keying.chroma.low/high): the key in 8-bit levels of
  // G - max(R, B) at the floor's brightness, k * Y_bg, where alpha is 1 (<= low) and 0 (>= high);
  // `high` never reaches into the floor's own noise (min_margin, noise_z). Else min_margin and
  // ramp.
  double key_low_levels = -1;
  double key_high_levels = -1;
  bool global_model = false;  // one reference for the whole frame: the naive keyer, for comparison
  // False with "FIELD: reason" in `why` when a value is out of its range.
  bool IsValid(std::string* why) const;
  bool operator==(const ChromaKeyerOptions&) const = default;
};

// The chroma keyer's block of the station config's keying section, keying.chroma.* (a
// KeyingConfig keyer block): the key difference in 8-bit levels where alpha starts to fall, and
// where it reaches 0; the config's defaults (ChromaKeyerOptions's own, -1, key by min_margin and
// ramp).
struct ChromaKeyBlock {
  double low = 20;
  double high = 60;
  bool operator==(const ChromaKeyBlock&) const = default;
};

// The options the station config's keying section sets (docs/keying.md, "From the station
// config"): its `chroma` block as key_low_levels and key_high_levels, with the shared blocks
// keying.despill and keying.shadow as they are.
ChromaKeyerOptions ChromaKeyerOptionsFrom(const KeyingConfig& keying);

class ChromaKeyer : public Keyer {
 public:
  explicit ChromaKeyer(ChromaKeyerOptions options = {});
  static constexpr const char* kMethod = "chroma";  // keying.method, and its block's key
  std::string name() const override { return kMethod; }
  void Train(const std::vector<cv::Mat>& empty_bgr) override;
  const ChromaKeyerOptions& options() const { return options_; }
  double unkeyable_fraction() const { return unkeyable_fraction_; }  // of cells, after Train
  // CV_8U, the trained size: 255 where the empty enclosure is green and keyed, 0 where it is
  // not (the room, a wall's outside, a cable): no subject is ever seen against those pixels.
  cv::Mat GreenMask() const;
  cv::Mat KeyableMask() const override { return GreenMask(); }

 protected:
  // Key and shadow are symmetric in R and B: only the colour layer minds the order.
  void SampleRow(const uint8_t* row, ChannelOrder order, int cell_row, uint8_t* foreground,
                 uint8_t* shade) const override;
  void FineRow(const uint8_t* row, ChannelOrder order, int y, int x0, int x1, uint8_t* alpha,
               uint8_t* shadow, uint8_t* colour) const override;

 private:
  // The key's parameters at one place, in the units of the kernel (luma4 =
  // B + 2G + R). Stored per cell for the coarse pass and, interpolated along x,
  // per pixel of each cell row ("band") for the fine pass.
  enum FloatParam { kKeyHi, kGain, kInvLuma, kShadowBase, kFloatParams };
  struct Params {
    const float* f[kFloatParams];  // indexed by FloatParam
    const int32_t* luma_floor;
  };
  Params BandParams(int cell_row) const;
  Params CellParams(int cell_row) const;

  ChromaKeyerOptions options_;
  std::vector<float> cell_f_;        // rows_ x kFloatParams x cols_: at each cell's sample
  std::vector<int32_t> cell_floor_;  // rows_ x cols_
  std::vector<float> band_f_;        // rows_ x kFloatParams x width: at every pixel of a cell row
  std::vector<int32_t> band_floor_;  // rows_ x width
  std::vector<uint8_t> keyable_;  // width x height: 0xFF where the empty enclosure is green, else 0
  std::vector<uint8_t>
      green_px_;  // width x height: 0xFF where the pixel's own training key is green
  double unkeyable_fraction_ = 0;
};

}  // namespace ss
