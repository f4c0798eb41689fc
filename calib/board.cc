#include "calib/board.h"

#include <cmath>
#include <cstdio>
#include <sstream>

#include <opencv2/aruco/dictionary.hpp>

#include "core/error.h"

namespace ss::calib {
namespace {

std::vector<std::string> Split(const std::string& text, char sep) {
  std::vector<std::string> parts;
  std::stringstream ss(text);
  std::string part;
  while (std::getline(ss, part, sep)) parts.push_back(part);
  return parts;
}

double PositiveMetres(const std::string& text, const std::string& field, const char* what) {
  size_t used = 0;
  double value = 0;
  try {
    value = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != text.size() || !std::isfinite(value) || value <= 0 || value > 10) {
    throw InputError(
        field, std::string("expected ") + what + " in metres (0 < m <= 10), got \"" + text + "\"");
  }
  return value;
}

}  // namespace

std::string BoardSpec::ToString() const {
  char buf[160];
  if (kind == BoardKind::kChessboard) {
    std::snprintf(buf, sizeof buf, "chessboard:%dx%d:%g", squares_x, squares_y, square_m);
  } else {
    std::snprintf(buf, sizeof buf, "charuco:%dx%d:%g:%g:%s", squares_x, squares_y, square_m,
                  marker_m, dictionary.c_str());
  }
  return buf;
}

int ArucoDictionaryId(const std::string& name) {
  static const std::pair<const char*, int> kNames[] = {
      {"DICT_4X4_50", cv::aruco::DICT_4X4_50},
      {"DICT_4X4_100", cv::aruco::DICT_4X4_100},
      {"DICT_4X4_250", cv::aruco::DICT_4X4_250},
      {"DICT_4X4_1000", cv::aruco::DICT_4X4_1000},
      {"DICT_5X5_50", cv::aruco::DICT_5X5_50},
      {"DICT_5X5_100", cv::aruco::DICT_5X5_100},
      {"DICT_5X5_250", cv::aruco::DICT_5X5_250},
      {"DICT_5X5_1000", cv::aruco::DICT_5X5_1000},
      {"DICT_6X6_50", cv::aruco::DICT_6X6_50},
      {"DICT_6X6_100", cv::aruco::DICT_6X6_100},
      {"DICT_6X6_250", cv::aruco::DICT_6X6_250},
      {"DICT_6X6_1000", cv::aruco::DICT_6X6_1000},
      {"DICT_7X7_50", cv::aruco::DICT_7X7_50},
      {"DICT_7X7_100", cv::aruco::DICT_7X7_100},
      {"DICT_7X7_250", cv::aruco::DICT_7X7_250},
      {"DICT_7X7_1000", cv::aruco::DICT_7X7_1000},
      {"DICT_ARUCO_ORIGINAL", cv::aruco::DICT_ARUCO_ORIGINAL},
  };
  for (const auto& [n, id] : kNames) {
    if (name == n) return id;
  }
  return -1;
}

BoardSpec ParseBoardSpec(const std::string& text, const std::string& field) {
  const auto parts = Split(text, ':');
  const std::string expected =
      "expected chessboard:COLSxROWS:SQUARE_M or charuco:COLSxROWS:SQUARE_M:MARKER_M[:DICT], got "
      "\"" +
      text + "\"";
  if (parts.size() < 3) throw InputError(field, expected);
  BoardSpec spec;
  if (parts[0] == "chessboard") {
    spec.kind = BoardKind::kChessboard;
    if (parts.size() != 3) throw InputError(field, expected);
  } else if (parts[0] == "charuco") {
    spec.kind = BoardKind::kCharuco;
    if (parts.size() != 4 && parts.size() != 5) throw InputError(field, expected);
  } else {
    throw InputError(field, "unknown board kind \"" + parts[0] + "\" (chessboard | charuco)");
  }
  int sx = 0, sy = 0;
  char x = 0, extra = 0;
  if (std::sscanf(parts[1].c_str(), "%d%c%d%c", &sx, &x, &sy, &extra) != 3 || x != 'x' || sx < 3 ||
      sy < 3 || sx > 200 || sy > 200) {
    throw InputError(
        field, "board size: expected COLSxROWS squares, each 3..200, got \"" + parts[1] + "\"");
  }
  spec.squares_x = sx;
  spec.squares_y = sy;
  spec.square_m = PositiveMetres(parts[2], field, "the square side");
  if (spec.kind == BoardKind::kCharuco) {
    spec.marker_m = PositiveMetres(parts[3], field, "the marker side");
    if (spec.marker_m >= spec.square_m) {
      throw InputError(field, "the ChArUco marker side must be smaller than the square side");
    }
    if (parts.size() == 5) spec.dictionary = parts[4];
    if (ArucoDictionaryId(spec.dictionary) < 0) {
      throw InputError(field,
                       "unknown ArUco dictionary \"" + spec.dictionary + "\" (e.g. DICT_4X4_50)");
    }
  }
  return spec;
}

}  // namespace ss::calib
