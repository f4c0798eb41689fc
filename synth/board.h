#pragma once
// Calibration boards the studio can show: a chessboard and a ChArUco board
// (OpenCV 4.6 contrib aruco), with their geometry in the board frame.
//
// Board frame (OpenCV's): origin at the top-left corner of the checkered area,
// x along the columns (right), y along the rows (down), z = x cross y, pointing
// *into* the board: the printed face is seen from the board's -z side.
// Inner-corner c (row-major, `squares_x - 1` per row) lies at
// ((col + 1) * square, (row + 1) * square, 0), the same points as
// cv::aruco::CharucoBoard::chessboardCorners. The top-left square is black.
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

namespace ss::synth {

enum class BoardKind { kChessboard, kCharuco };

struct BoardSpec {
  BoardKind kind = BoardKind::kChessboard;
  int squares_x = 10;      // squares along x
  int squares_y = 7;       // squares along y
  double square_m = 0.03;  // side of one square
  double marker_m = 0.0;   // ChArUco marker side
  std::string dictionary;  // ChArUco: "DICT_4X4_50"
  double margin_m = 0.02;  // white border around the checkered area

  std::string Name() const { return kind == BoardKind::kChessboard ? "chessboard" : "charuco"; }
  double width_m() const { return squares_x * square_m; }
  double height_m() const { return squares_y * square_m; }
  // Inner corners (squares_x - 1) x (squares_y - 1) in the board frame, row-major.
  std::vector<Eigen::Vector3d> InnerCorners() const;
  // Pattern size for cv::findChessboardCorners: (squares_x - 1, squares_y - 1).
  cv::Size PatternSize() const { return {squares_x - 1, squares_y - 1}; }
};

// The printed pattern of one board, sampled in board coordinates.
class BoardTexture {
 public:
  explicit BoardTexture(const BoardSpec& spec);
  const BoardSpec& spec() const { return spec_; }
  // 1 where the print is white, 0 where black, -1 off the board; (x, y) in metres.
  int Sample(double x, double y) const;

 private:
  BoardSpec spec_;
  cv::Mat charuco_;  // ChArUco print, 8-bit, kTexelsPerMetre
  double texels_per_m_ = 0;
};

// The studio's boards: sized for the enclosure (small) or the stage (large).
BoardSpec ChessboardFor(bool stage);
BoardSpec CharucoFor(bool stage);

}  // namespace ss::synth
