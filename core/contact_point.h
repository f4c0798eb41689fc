#pragma once
// The contact point of a sprite (seed 000 §2.1): the image point whose ray,
// cast to the floor, gives the subject's ground position. One definition,
// used by the extractor (pipeline/extract) and by the synthetic truth
// (synth/studio_session), so that both measure the same thing (docs/pipeline.md).
//
// y: where alpha falls through 1/2 below the silhouette's lowest row (the
// lowest sprite point, interpolated). x: the alpha-weighted centre of the
// silhouette's bottom band, a band `band_fraction` of the silhouette's height
// tall (at least `min_band_px`), weighted by a ramp that is 1 at the bottom
// and 0 at the band's top. A paw that becomes the lowest, or a second paw that
// reaches the band, moves the point continuously instead of making it jump
// from one paw to the other.
#include <string>

#include <opencv2/core.hpp>

namespace ss {

struct ContactPointOptions {
  // the bottom band's height, as a fraction (0..1) of the silhouette's height (top row to the
  // lowest point)
  double band_fraction = 0.1;
  double min_band_px = 3.0;  // the band is never thinner than this, px (> 0)
  // False with "FIELD: reason" lines in `why` (core/option_checks.h) for values out of range.
  bool IsValid(std::string* why) const;
  bool operator==(const ContactPointOptions&) const = default;
};

// The contact point of the silhouette in `alpha` (CV_8U, 255 = subject), in
// `alpha`'s pixel coordinates (pixel centres at integers). False when no
// pixel has alpha > 1/2. InputError ("contact point options") for options out of range.
bool ContactPoint(const cv::Mat& alpha, cv::Point2d* point,
                  const ContactPointOptions& options = {});

}  // namespace ss
