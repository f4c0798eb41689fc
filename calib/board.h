#pragma once
// The calibration board as the calibration code sees it: a chessboard or a
// ChArUco board (OpenCV 4.6 contrib aruco), parsed from a one-line spec.
//
// Board frame (OpenCV's, the same as synth/board.h): origin at the top-left
// corner of the checkered area, x along the columns, y along the rows, z into
// the board. Inner corner id = row * (squares_x - 1) + col lies at
// ((col + 1) * square_m, (row + 1) * square_m, 0).
#include <string>
#include <vector>

#include <Eigen/Core>

namespace ss::calib {

enum class BoardKind { kChessboard, kCharuco };

struct BoardSpec {
  BoardKind kind = BoardKind::kChessboard;
  int squares_x = 10;                      // squares along x (columns)
  int squares_y = 7;                       // squares along y (rows)
  double square_m = 0.03;                  // side of one square, metres
  double marker_m = 0.0;                   // ChArUco: side of one marker, metres
  std::string dictionary = "DICT_4X4_50";  // ChArUco: OpenCV predefined dictionary name

  int corners_x() const { return squares_x - 1; }  // inner corners per row
  int corners_y() const { return squares_y - 1; }  // inner corner rows
  int corner_count() const { return corners_x() * corners_y(); }
  // Inner corner `id` in the board frame.
  Eigen::Vector3d Corner(int id) const {
    return {(id % corners_x() + 1) * square_m, (id / corners_x() + 1) * square_m, 0.0};
  }
  // "chessboard:10x7:0.03" or "charuco:10x7:0.03:0.022:DICT_4X4_50".
  std::string ToString() const;
};

// Parses "chessboard:COLSxROWS:SQUARE_M" or
// "charuco:COLSxROWS:SQUARE_M:MARKER_M[:DICT]" (COLS, ROWS count squares; sizes
// in metres). InputError naming `field` and what was expected.
BoardSpec ParseBoardSpec(const std::string& text, const std::string& field = "--board");

// OpenCV's id for a predefined ArUco dictionary name ("DICT_4X4_50" ...); -1 when unknown.
int ArucoDictionaryId(const std::string& name);

}  // namespace ss::calib
