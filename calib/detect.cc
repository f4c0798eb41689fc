#include "calib/detect.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include <opencv2/aruco/charuco.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "core/option_checks.h"

namespace ss::calib {
namespace {

cv::Mat ToGrey(const cv::Mat& image) {
  if (image.empty()) return {};
  cv::Mat grey;
  if (image.channels() == 3) {
    cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  } else if (image.channels() == 4) {
    cv::cvtColor(image, grey, cv::COLOR_BGRA2GRAY);
  } else {
    grey = image;
  }
  if (grey.depth() != CV_8U) grey.convertTo(grey, CV_8U);
  return grey;
}

float SampleBilinear(const cv::Mat& grey, double x, double y) {
  const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
  if (x0 < 0 || y0 < 0 || x0 + 1 >= grey.cols || y0 + 1 >= grey.rows) return NAN;
  const double fx = x - x0, fy = y - y0;
  const auto at = [&](int yy, int xx) { return static_cast<double>(grey.at<uint8_t>(yy, xx)); };
  return static_cast<float>((1 - fy) * ((1 - fx) * at(y0, x0) + fx * at(y0, x0 + 1)) +
                            fy * ((1 - fx) * at(y0 + 1, x0) + fx * at(y0 + 1, x0 + 1)));
}

// 10-90% rise of the intensity profile across the edge through `mid`, along unit `normal`.
double EdgeRise(const cv::Mat& grey, const Eigen::Vector2d& mid, const Eigen::Vector2d& normal,
                double half) {
  constexpr double kStep = 0.25;
  const int n = static_cast<int>(std::floor(half / kStep));
  if (n < 4) return NAN;
  std::vector<double> p;
  for (int i = -n; i <= n; ++i) {
    const Eigen::Vector2d q = mid + normal * (i * kStep);
    const float v = SampleBilinear(grey, q.x(), q.y());
    if (std::isnan(v)) return NAN;
    p.push_back(v);
  }
  const int tail = std::max(1, static_cast<int>(p.size()) / 7);
  const double a = std::accumulate(p.begin(), p.begin() + tail, 0.0) / tail;
  const double b = std::accumulate(p.end() - tail, p.end(), 0.0) / tail;
  if (std::abs(b - a) < 20) return NAN;  // no contrast: not an edge we can measure
  for (double& v : p) v = (v - a) / (b - a);
  // The 50% crossing nearest the middle, then outwards to 10% and 90%.
  const int centre = n;
  int c50 = -1;
  for (int d = 0; d < n && c50 < 0; ++d) {
    for (int s : {centre - d, centre + d}) {
      if (s >= 0 && s + 1 < static_cast<int>(p.size()) && (p[s] - 0.5) * (p[s + 1] - 0.5) <= 0) {
        c50 = s;
        break;
      }
    }
  }
  if (c50 < 0) return 2 * half;
  auto crossing = [&](double level, int from, int dir) {
    for (int s = from; s >= 0 && s + 1 < static_cast<int>(p.size()); s += dir) {
      if ((p[s] - level) * (p[s + 1] - level) <= 0 && p[s] != p[s + 1]) {
        return (s + (level - p[s]) / (p[s + 1] - p[s])) * kStep;
      }
    }
    return dir < 0 ? 0.0 : (p.size() - 1) * kStep;
  };
  return crossing(0.9, c50, +1) - crossing(0.1, c50, -1);
}

void SortById(std::vector<int>& ids, std::vector<Eigen::Vector2d>& pixels) {
  std::vector<size_t> order(ids.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return ids[a] < ids[b]; });
  std::vector<int> sorted_ids;
  std::vector<Eigen::Vector2d> sorted_pixels;
  for (size_t i : order) {
    sorted_ids.push_back(ids[i]);
    sorted_pixels.push_back(pixels[i]);
  }
  ids = std::move(sorted_ids);
  pixels = std::move(sorted_pixels);
}

// findChessboardCornersSB may order the grid mirrored or turned by 180 degrees;
// puts it in the board's own order (printed face seen, top-left square black).
void NormalizeChessboardOrder(const BoardSpec& board, const cv::Mat& grey,
                              std::vector<Eigen::Vector2d>& pixels) {
  const int cx = board.corners_x(), cy = board.corners_y();
  auto at = [&](int row, int col) -> Eigen::Vector2d& { return pixels[row * cx + col]; };
  const Eigen::Vector2d dx = at(0, 1) - at(0, 0), dy = at(1, 0) - at(0, 0);
  if (dx.x() * dy.y() - dx.y() * dy.x() < 0) {  // mirrored: the columns run backwards
    for (int r = 0; r < cy; ++r)
      std::reverse(pixels.begin() + r * cx, pixels.begin() + (r + 1) * cx);
  }
  std::vector<cv::Point2f> src, dst;
  for (int id = 0; id < board.corner_count(); ++id) {
    const Eigen::Vector3d p = board.Corner(id) / board.square_m;
    src.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()));
    dst.emplace_back(static_cast<float>(pixels[id].x()), static_cast<float>(pixels[id].y()));
  }
  const cv::Mat h = cv::findHomography(src, dst, 0);
  if (h.empty()) return;
  auto square_mean = [&](double sx, double sy) {  // mean grey over the inner half of a square
    double sum = 0;
    int count = 0;
    for (double u = -0.2; u <= 0.21; u += 0.1) {
      for (double v = -0.2; v <= 0.21; v += 0.1) {
        std::vector<cv::Point2d> in{{sx + u, sy + v}}, out;
        cv::perspectiveTransform(in, out, h);
        const float g = SampleBilinear(grey, out[0].x, out[0].y);
        if (!std::isnan(g)) sum += g, ++count;
      }
    }
    return count ? sum / count : NAN;
  };
  const double top_left = square_mean(0.5, 0.5), next = square_mean(1.5, 0.5);
  if (!std::isnan(top_left) && !std::isnan(next) && top_left > next) {
    std::reverse(pixels.begin(), pixels.end());  // turned by 180 degrees
  }
}

void DetectChessboard(const BoardSpec& board, const cv::Mat& grey, const DetectOptions& options,
                      BoardView& view) {
  std::vector<cv::Point2f> corners;
  const bool exhaustive = options.exhaustive;
  const bool found = cv::findChessboardCornersSB(
      grey, cv::Size(board.corners_x(), board.corners_y()), corners,
      cv::CALIB_CB_NORMALIZE_IMAGE | (exhaustive ? cv::CALIB_CB_EXHAUSTIVE : 0) |
          cv::CALIB_CB_ACCURACY);
  if (!found || static_cast<int>(corners.size()) != board.corner_count()) {
    view.rejection = "no chessboard with " + std::to_string(board.corners_x()) + "x" +
                     std::to_string(board.corners_y()) + " inner corners found";
    return;
  }
  // findChessboardCornersSB's corners carry a per-corner bias of ~0.1 px on
  // small squares (a fixed pattern, not noise: averaging still views keeps it;
  // with the enclosure's floor board it tilted the ground pose by 0.39 deg).
  // cornerSubPix with a window inside one square removes it.
  double spacing = 1e9;
  for (int r = 0; r < board.corners_y(); ++r) {
    for (int c = 0; c < board.corners_x(); ++c) {
      const int i = r * board.corners_x() + c;
      if (c + 1 < board.corners_x())
        spacing = std::min(spacing, static_cast<double>(cv::norm(corners[i] - corners[i + 1])));
      if (r + 1 < board.corners_y()) {
        spacing = std::min(
            spacing, static_cast<double>(cv::norm(corners[i] - corners[i + board.corners_x()])));
      }
    }
  }
  const int half = std::clamp(static_cast<int>(spacing / 2), 2, 5);
  cv::cornerSubPix(grey, corners, cv::Size(half, half), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 40, 0.001));
  for (int id = 0; id < board.corner_count(); ++id) {
    view.ids.push_back(id);
    view.pixels.emplace_back(corners[id].x, corners[id].y);
  }
  NormalizeChessboardOrder(board, grey, view.pixels);
}

void DetectCharuco(const BoardSpec& board, const cv::Mat& grey, BoardView& view) {
  const auto dict = cv::aruco::getPredefinedDictionary(ArucoDictionaryId(board.dictionary));
  const auto charuco = cv::aruco::CharucoBoard::create(board.squares_x, board.squares_y,
                                                       static_cast<float>(board.square_m),
                                                       static_cast<float>(board.marker_m), dict);
  std::vector<std::vector<cv::Point2f>> marker_corners, rejected;
  std::vector<int> marker_ids;
  auto params = cv::aruco::DetectorParameters::create();
  cv::aruco::detectMarkers(grey, dict, marker_corners, marker_ids, params, rejected);
  if (marker_ids.empty()) {
    view.rejection = "no " + board.dictionary + " markers found";
    return;
  }
  const int board_markers = static_cast<int>(charuco->ids.size());
  int own = 0;
  for (int id : marker_ids) own += (id >= 0 && id < board_markers) ? 1 : 0;
  if (own == 0) {
    view.rejection = std::to_string(marker_ids.size()) +
                     " markers found, none with an id of this " + std::to_string(board.squares_x) +
                     "x" + std::to_string(board.squares_y) + " board (0.." +
                     std::to_string(board_markers - 1) + "): does the board spec match?";
    return;
  }
  std::vector<cv::Point2f> corners;
  std::vector<int> ids;
  cv::aruco::interpolateCornersCharuco(marker_corners, marker_ids, grey, charuco, corners, ids);
  if (ids.empty()) {
    view.rejection = std::to_string(own) + " markers found but no ChArUco corner could be placed";
    return;
  }
  // interpolateCornersCharuco refines with a window sized for the whole
  // square; a small window keeps the marker's own corners out of it.
  double spacing = 1e9;
  for (size_t i = 0; i + 1 < corners.size(); ++i) {
    spacing = std::min(spacing, static_cast<double>(cv::norm(corners[i] - corners[i + 1])));
  }
  const int half = std::clamp(
      static_cast<int>(spacing * (board.square_m - board.marker_m) / board.square_m / 2.5), 2, 5);
  cv::cornerSubPix(grey, corners, cv::Size(half, half), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 40, 0.005));
  for (size_t i = 0; i < ids.size(); ++i) {
    view.ids.push_back(ids[i]);
    view.pixels.emplace_back(corners[i].x, corners[i].y);
  }
  SortById(view.ids, view.pixels);
}

// Rows and columns spanned by the detected ids, and the corners' hull area.
void CheckGeometry(const BoardSpec& board, const DetectOptions& options, BoardView& view) {
  if (static_cast<int>(view.ids.size()) < options.min_corners) {
    view.rejection = "too few corners (" + std::to_string(view.ids.size()) + " < " +
                     std::to_string(options.min_corners) + ")";
    return;
  }
  std::vector<int> rows, cols;
  for (int id : view.ids)
    rows.push_back(id / board.corners_x()), cols.push_back(id % board.corners_x());
  std::sort(rows.begin(), rows.end());
  std::sort(cols.begin(), cols.end());
  const auto distinct = [](std::vector<int>& v) {
    return std::unique(v.begin(), v.end()) - v.begin();
  };
  if (distinct(rows) < 2 || distinct(cols) < 2) {
    view.rejection = "degenerate: the detected corners lie on one line of the board";
    return;
  }
  std::vector<cv::Point2f> points, hull;
  for (const auto& p : view.pixels)
    points.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()));
  cv::convexHull(points, hull);
  const double fraction = cv::contourArea(hull) / (static_cast<double>(view.width) * view.height);
  if (fraction < options.min_area_fraction) {
    view.rejection = "degenerate: the board covers " + std::to_string(fraction * 100).substr(0, 4) +
                     "% of the image (move it closer)";
  }
}

}  // namespace

double MeasureEdgeWidth(const BoardSpec& board, const cv::Mat& grey, const std::vector<int>& ids,
                        const std::vector<Eigen::Vector2d>& pixels) {
  std::vector<int> index(board.corner_count(), -1);
  for (size_t i = 0; i < ids.size(); ++i) {
    if (ids[i] >= 0 && ids[i] < board.corner_count()) index[ids[i]] = static_cast<int>(i);
  }
  // Half length of the profile as a fraction of the corner spacing: it must stay
  // off the next edge (chessboard) or the marker inside a white square (ChArUco).
  const double reach =
      board.kind == BoardKind::kChessboard
          ? 0.4
          : std::min(0.4, 0.85 * (board.square_m - board.marker_m) / 2 / board.square_m);
  std::vector<double> widths;
  const int cx = board.corners_x();
  for (int id = 0; id < board.corner_count(); ++id) {
    if (index[id] < 0) continue;
    for (int neighbour :
         {id % cx + 1 < cx ? id + 1 : -1, id + cx < board.corner_count() ? id + cx : -1}) {
      if (neighbour < 0 || index[neighbour] < 0) continue;
      const Eigen::Vector2d &a = pixels[index[id]], &b = pixels[index[neighbour]];
      const Eigen::Vector2d along = b - a;
      const double spacing = along.norm();
      if (spacing < 4) continue;
      const Eigen::Vector2d normal(-along.y() / spacing, along.x() / spacing);
      const double w = EdgeRise(grey, (a + b) / 2, normal, reach * spacing);
      if (!std::isnan(w)) widths.push_back(w);
    }
  }
  if (widths.empty()) return NAN;
  std::nth_element(widths.begin(), widths.begin() + widths.size() / 2, widths.end());
  return widths[widths.size() / 2];
}

bool DetectOptions::IsValid(std::string* why) const {
  OptionProblems check(why);
  check.Within(max_edge_width_px, Positive(), "max_edge_width_px", "a positive number of pixels");
  check.Within(min_corners, AtLeast(4), "min_corners", "at least 4 (a board pose needs 4 corners)");
  check.Within(min_area_fraction, Between(0, 1), "min_area_fraction", "a fraction 0..1");
  return check.ok();
}

BoardView DetectBoard(const BoardSpec& board, const cv::Mat& image, const DetectOptions& options,
                      const std::string& source) {
  if (std::string why; !options.IsValid(&why)) throw InputError("board detection options", why);
  BoardView view;
  view.source = source;
  const cv::Mat grey = ToGrey(image);
  if (grey.empty()) {
    view.rejection = "empty image";
    return view;
  }
  view.width = grey.cols;
  view.height = grey.rows;
  if (board.kind == BoardKind::kChessboard) {
    DetectChessboard(board, grey, options, view);
  } else {
    DetectCharuco(board, grey, view);
  }
  if (!view.rejection.empty()) return view;
  CheckGeometry(board, options, view);
  if (!view.rejection.empty()) return view;
  view.edge_width_px = MeasureEdgeWidth(board, grey, view.ids, view.pixels);
  if (options.check_sharpness && view.edge_width_px > options.max_edge_width_px) {
    char buf[128];
    std::snprintf(buf, sizeof buf, "blurred: square edges rise over %.1f px (limit %.1f px)",
                  view.edge_width_px, options.max_edge_width_px);
    view.rejection = buf;
    return view;
  }
  view.accepted = true;
  return view;
}

}  // namespace ss::calib
