#pragma once
// Keyer for backgrounds that are not green: difference against a clean plate
// (the mean of empty-enclosure frames) with a per-pixel noise model (their
// spread). The difference is split as in Horprasert et al. (1999): the plate
// colour scaled by a brightness ratio a = (p . mu) / (mu . mu), and what is
// left, the chromaticity distortion |p - a mu|. A shadow only changes a, so a
// darkening 1 - a within the noise of the plate's colour is shadow, not
// subject; colour changes, brightening, and darkening below `dark_floor` are
// subject. See docs/keying.md.
#include <vector>

#include "pipeline/key/keyer.h"
#include "pipeline/key/shared_options.h"

namespace ss {

struct KeyingConfig;

struct CleanPlateKeyerOptions {
  GridOptions grid;
  // Background tolerance in noise sigmas (the false-positive rate of a 1-D z test): the
  // difference where alpha starts to rise.
  double low_sigma = 4.0;
  double min_sigma = 2.0;  // noise std floor, levels of 255 (a single empty frame has no spread)
  double ramp = 30.0;      // alpha goes 0 -> 1 over this many levels beyond the tolerance
  double coarse_alpha = 0.25;   // a sample with a larger alpha marks its cell as foreground
  double coarse_shadow = 0.12;  // a sample darkened more marks its cell as shaded
  // > 0: alpha reaches 1 at this many of the plate's noise sigmas (the ramp is high_sigma -
  // low_sigma of the mean sigma) instead of `ramp` levels beyond the tolerance.
  double high_sigma = 0;
  // The contact shadow: darker than (1 - max_darkening) of the plate is subject, not shadow.
  ShadowOptions shadow = {true, 0.06, 0.7};
  // False with "FIELD: reason" in `why` when a value is out of its range.
  bool IsValid(std::string* why) const;
  bool operator==(const CleanPlateKeyerOptions&) const = default;
};

// The clean-plate keyer's block of the station config's keying section, keying.clean_plate.* (a
// KeyingConfig keyer block): the ramp in noise sigmas, the config's defaults (the keyer's own,
// 4 and 0, ramp by levels).
struct CleanPlateKeyBlock {
  double low_sigma = 3;
  double high_sigma = 6;
  bool operator==(const CleanPlateKeyBlock&) const = default;
};

// The options the station config's keying section sets (docs/keying.md, "From the station
// config"): its `clean_plate` block as low_sigma and high_sigma, with the shared block
// keying.shadow as it is.
CleanPlateKeyerOptions CleanPlateKeyerOptionsFrom(const KeyingConfig& keying);

class CleanPlateKeyer : public Keyer {
 public:
  explicit CleanPlateKeyer(CleanPlateKeyerOptions options = {});
  static constexpr const char* kMethod = "clean_plate";  // keying.method, and its block's key
  std::string name() const override { return "clean-plate"; }
  void Train(const std::vector<cv::Mat>& empty_bgr) override;
  const CleanPlateKeyerOptions& options() const { return options_; }
  const cv::Mat& plate() const { return plate_; }  // CV_8UC3, mean empty frame
  const cv::Mat& tolerance() const {
    return tolerance_;
  }                                             // CV_32F, levels, per pixel (docs/keying.md)
  double ramp_levels() const { return ramp_; }  // alpha's ramp beyond the tolerance (after Train)

 protected:
  void SampleRow(const uint8_t* row, ChannelOrder order, int cell_row, uint8_t* foreground,
                 uint8_t* shade) const override;
  void FineRow(const uint8_t* row, ChannelOrder order, int y, int x0, int x1, uint8_t* alpha,
               uint8_t* shadow, uint8_t* colour) const override;

 private:
  CleanPlateKeyerOptions options_;
  cv::Mat plate_;
  cv::Mat tolerance_;
  double ramp_ = 0;       // levels, set by Train
  int ShadowMin() const;  // levels; 256 (never reached) when the shadow layer is off
};

}  // namespace ss
