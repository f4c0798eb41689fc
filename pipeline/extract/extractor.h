#pragma once
// Sprite candidates from a keyed frame: one per connected region of the
// keyer's coarse grid (the connected components, found at 1/step resolution
// by the keyer), cut to the subject's box. Blobs smaller than `min_area` are
// noise: dropped and counted.
#include <cstdint>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "core/contact_point.h"
#include "pipeline/key/matte.h"

namespace ss {

struct Candidate {
  int region = 0;               // the KeyRegion id it came from
  cv::Rect bbox;                // frame pixels: subject box + margin, grown to hold its shadow
  cv::Mat alpha;                // CV_8U, bbox-sized
  cv::Mat colour;               // CV_8UC3, bbox-sized, spill removed
  cv::Mat shadow;               // CV_8U, bbox-sized contact shadow (floor darkening, 255 = black)
  cv::Point2d contact_point;    // frame pixels: the sprite's contact point (core/contact_point.h):
                                // y the lowest point, x the centre of the silhouette's bottom band
  double area = 0;              // sum of alpha / 255, pixels
  bool touches_border = false;  // the subject (alpha >= alpha_min) reaches the frame's edge
};

struct ExtractorOptions {
  // Pixels of alpha; smaller blobs are noise (the station config's pipeline.min_area_px, whose
  // default is 400: config/station_config.h, DefaultPipelineOptions).
  int min_area = 40;
  int margin_px = 4;    // added around the subject's alpha box
  int alpha_min = 16;   // alpha (of 255) that counts as subject for the box and the border test
  int shadow_min = 16;  // shadow (of 255) that counts for the box
  ContactPointOptions contact;  // the contact point's bottom band
  // False with "FIELD: reason" lines in `why` (core/option_checks.h) for values out of range.
  bool IsValid(std::string* why) const;
  bool operator==(const ExtractorOptions&) const = default;
};

struct ExtractTotals {
  uint64_t frames = 0;
  uint64_t candidates = 0;
  uint64_t noise_dropped = 0;  // blobs below min_area
};

class Extractor {
 public:
  explicit Extractor(ExtractorOptions options = {});
  // The candidates of one keyed frame. They borrow the extractor's buffers,
  // reused by the next call: clone what must outlive it.
  const std::vector<Candidate>& Extract(const Matte& matte);
  int dropped_last() const { return dropped_last_; }  // noise blobs dropped by the last call
  const ExtractTotals& totals() const { return totals_; }
  const ExtractorOptions& options() const { return options_; }

 private:
  struct Storage {  // grows, never shrinks: no allocation once warm
    std::vector<uint8_t> alpha, colour, shadow;
  };
  // Builds candidate `index` from region `r`; false when it is noise.
  bool Cut(const Matte& matte, const KeyRegion& r, size_t index);

  ExtractorOptions options_;
  std::vector<Candidate> candidates_;
  std::vector<Storage> storage_;
  cv::Mat masked_alpha_, masked_shadow_;  // scratch for regions whose boxes overlap
  int dropped_last_ = 0;
  ExtractTotals totals_;
};

}  // namespace ss
