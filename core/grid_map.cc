#include "core/grid_map.h"

#include <opencv2/core.hpp>

namespace ss {

void InterpolateGridMap(const std::vector<Eigen::Vector2f>& grid, int step, cv::Size size,
                        std::optional<float> outside, cv::Mat& map) {
  const int gw = GridPoints(size.width, step);
  map.create(size, CV_32FC2);
  for (int y = 0; y < size.height; ++y) {
    const int gy = y / step;
    const float fy = static_cast<float>(y - gy * step) / step;
    auto* row = map.ptr<cv::Vec2f>(y);
    for (int x = 0; x < size.width; ++x) {
      const int gx = x / step;
      const float fx = static_cast<float>(x - gx * step) / step;
      const Eigen::Vector2f& a = grid[gy * gw + gx];
      const Eigen::Vector2f& b = grid[gy * gw + gx + 1];
      const Eigen::Vector2f& c = grid[(gy + 1) * gw + gx];
      const Eigen::Vector2f& d = grid[(gy + 1) * gw + gx + 1];
      if (outside &&
          (a.x() == *outside || b.x() == *outside || c.x() == *outside || d.x() == *outside)) {
        row[x] = cv::Vec2f(*outside, *outside);
        continue;
      }
      const Eigen::Vector2f p = (1 - fy) * ((1 - fx) * a + fx * b) + fy * ((1 - fx) * c + fx * d);
      row[x] = cv::Vec2f(p.x(), p.y());
    }
  }
}

}  // namespace ss
