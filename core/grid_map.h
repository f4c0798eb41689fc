#pragma once
// A dense remap interpolated from a coarse grid: where each map value is expensive (a lens
// model, a ray cast onto a plane), the renderer and the rectifier compute it at every `step`
// pixels only and fill the pixels in between bilinearly.
#include <optional>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>

namespace ss {

// The grid's width in points for a map `width` pixels wide: ceil(width / step) + 1.
inline int GridPoints(int width, int step) { return (width + step - 1) / step + 1; }

// Fills `map` (CV_32FC2 of `size`, for cv::remap) from `grid`, the map's values at pixels
// (gx * step, gy * step), row by row, GridPoints(size.width, step) a row. With `outside` set, a
// grid point whose x is *outside has no value: every pixel of a cell that touches one gets
// (*outside, *outside).
void InterpolateGridMap(const std::vector<Eigen::Vector2f>& grid, int step, cv::Size size,
                        std::optional<float> outside, cv::Mat& map);

}  // namespace ss
