#include "synth/board.h"

#include <cmath>

#include <opencv2/aruco/charuco.hpp>

#include "core/error.h"

namespace ss::synth {

std::vector<Eigen::Vector3d> BoardSpec::InnerCorners() const {
  std::vector<Eigen::Vector3d> corners;
  for (int row = 0; row < squares_y - 1; ++row) {
    for (int col = 0; col < squares_x - 1; ++col) {
      corners.emplace_back((col + 1) * square_m, (row + 1) * square_m, 0.0);
    }
  }
  return corners;
}

BoardTexture::BoardTexture(const BoardSpec& spec) : spec_(spec) {
  if (spec.kind == BoardKind::kCharuco) {
    if (spec.dictionary != "DICT_4X4_50")
      throw InputError("board.dictionary", "only DICT_4X4_50 is drawn");
    auto dict = cv::aruco::getPredefinedDictionary(cv::aruco::DICT_4X4_50);
    auto board = cv::aruco::CharucoBoard::create(spec.squares_x, spec.squares_y,
                                                 static_cast<float>(spec.square_m),
                                                 static_cast<float>(spec.marker_m), dict);
    texels_per_m_ = 200.0 / spec.square_m;  // 200 texels per square
    const cv::Size size(static_cast<int>(std::lround(spec.width_m() * texels_per_m_)),
                        static_cast<int>(std::lround(spec.height_m() * texels_per_m_)));
    board->draw(size, charuco_, 0, 1);
  }
}

int BoardTexture::Sample(double x, double y) const {
  const double m = spec_.margin_m;
  if (x < -m || y < -m || x > spec_.width_m() + m || y > spec_.height_m() + m) return -1;
  if (x < 0 || y < 0 || x >= spec_.width_m() || y >= spec_.height_m()) return 1;
  if (spec_.kind == BoardKind::kChessboard) {
    const int col = static_cast<int>(std::floor(x / spec_.square_m));
    const int row = static_cast<int>(std::floor(y / spec_.square_m));
    return ((col + row) % 2 == 0) ? 0 : 1;
  }
  const int u = std::min(charuco_.cols - 1, static_cast<int>(x * texels_per_m_));
  const int v = std::min(charuco_.rows - 1, static_cast<int>(y * texels_per_m_));
  return charuco_.at<uint8_t>(v, u) > 127 ? 1 : 0;
}

BoardSpec ChessboardFor(bool stage) {
  BoardSpec board{.kind = BoardKind::kChessboard, .squares_x = 10, .squares_y = 7};
  board.square_m = board.margin_m = stage ? 0.07 : 0.03;
  return board;
}

BoardSpec CharucoFor(bool stage) {
  BoardSpec board{
      .kind = BoardKind::kCharuco, .squares_x = 7, .squares_y = 5, .dictionary = "DICT_4X4_50"};
  board.square_m = stage ? 0.09 : 0.04;
  board.marker_m = board.square_m * 0.75;
  board.margin_m = board.square_m * 0.5;
  return board;
}

}  // namespace ss::synth
