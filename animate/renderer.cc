#include "animate/renderer.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "core/grid_map.h"
#include "core/option_checks.h"

namespace ss {
namespace {

// BGRA 8-bit straight alpha -> premultiplied float BGRA.
cv::Mat Premultiply(const cv::Mat& bgra) {
  cv::Mat out(bgra.size(), CV_32FC4);
  for (int y = 0; y < bgra.rows; ++y) {
    const auto* in = bgra.ptr<cv::Vec4b>(y);
    auto* o = out.ptr<cv::Vec4f>(y);
    for (int x = 0; x < bgra.cols; ++x) {
      const float a = in[x][3] / 255.0f;
      o[x] = cv::Vec4f(in[x][0] * a, in[x][1] * a, in[x][2] * a, a * 255.0f);
    }
  }
  return out;
}

// A shadow layer as premultiplied black with alpha = opacity * shadow.
cv::Mat ShadowLayer(const cv::Mat& shadow, double opacity) {
  cv::Mat out(shadow.size(), CV_32FC4);
  for (int y = 0; y < shadow.rows; ++y) {
    const auto* in = shadow.ptr<uint8_t>(y);
    auto* o = out.ptr<cv::Vec4f>(y);
    for (int x = 0; x < shadow.cols; ++x) {
      o[x] = cv::Vec4f(0, 0, 0, static_cast<float>(std::clamp(opacity, 0.0, 1.0) * in[x]));
    }
  }
  return out;
}

}  // namespace

bool RenderOptions::IsValid(std::string* why) const {
  OptionProblems check(why);
  check.Within(shadow_opacity, Between(0, 1), "shadow_opacity", "a fraction 0..1");
  check.Within(grid_step_px, AtLeast(1), "grid_step_px", "at least 1");
  check.Within(min_floor_view_deg, Between(0, 90), "min_floor_view_deg", "degrees 0..90");
  check.Within(max_upright_view_deg, Between(0, 90), "max_upright_view_deg", "degrees 0..90");
  return check.ok();
}

SpriteRenderer::SpriteRenderer(CameraModel camera, const cv::Mat& background, RenderOptions options)
    : camera_(std::move(camera)), options_(options) {
  if (!camera_.valid()) throw InputError("camera", "no camera model");
  if (std::string why; !options_.IsValid(&why)) throw InputError("render options", why);
  centre_in_ground_ = camera_.CentreInGround();
  if (!background.empty()) {
    if (background.cols != camera_.width() || background.rows != camera_.height()) {
      throw InputError("background", "is " + std::to_string(background.cols) + "x" +
                                         std::to_string(background.rows) + ", the camera " +
                                         std::to_string(camera_.width()) + "x" +
                                         std::to_string(camera_.height()));
    }
    cv::Mat bgra;
    if (background.channels() == 3) {
      cv::cvtColor(background, bgra, cv::COLOR_BGR2BGRA);
    } else if (background.channels() == 4) {
      bgra = background;
    } else if (background.channels() == 1) {
      cv::cvtColor(background, bgra, cv::COLOR_GRAY2BGRA);
    } else {
      throw InputError("background", "expected a grey, BGR or BGRA image");
    }
    if (bgra.depth() != CV_8U) throw InputError("background", "expected an 8-bit image");
    background_ = Premultiply(bgra);
  }
}

Eigen::Vector2d SpriteRenderer::TowardCamera(const Eigen::Vector2d& ground_m) const {
  Eigen::Vector2d toward = centre_in_ground_.head<2>() - ground_m;
  if (toward.norm() < 1e-9) return Eigen::Vector2d(0, -1);  // straight above: any direction
  return toward.normalized();
}

double SpriteRenderer::ViewAngleDeg(const Eigen::Vector2d& ground_m) const {
  return std::atan2(centre_in_ground_.z(), (centre_in_ground_.head<2>() - ground_m).norm()) * 180 /
         M_PI;
}

void SpriteRenderer::DrawPlane(const cv::Mat& full_layer, const Eigen::Vector3d& full_origin,
                               const Eigen::Vector3d& full_du, const Eigen::Vector3d& full_dv,
                               cv::Mat* canvas) const {
  // A layer seen smaller than its pixels is first shrunk by area averaging (premultiplied,
  // so edges stay clean); point sampling alone would alias away thin details.
  cv::Mat layer = full_layer;
  Eigen::Vector3d origin = full_origin, du = full_du, dv = full_dv;
  {
    const Eigen::Vector2d a = camera_.ProjectGround(origin);
    const Eigen::Vector2d b = camera_.ProjectGround(origin + du * layer.cols);
    const Eigen::Vector2d c = camera_.ProjectGround(origin + dv * layer.rows);
    if (!a.allFinite() || !b.allFinite() || !c.allFinite()) return;
    const double fx = std::min(1.0, (b - a).norm() / layer.cols);
    const double fy = std::min(1.0, (c - a).norm() / layer.rows);
    if (fx < 0.75 || fy < 0.75) {
      const int w = std::max(1, static_cast<int>(std::lround(layer.cols * fx)));
      const int h = std::max(1, static_cast<int>(std::lround(layer.rows * fy)));
      const double rx = static_cast<double>(layer.cols) / w,
                   ry = static_cast<double>(layer.rows) / h;
      cv::resize(full_layer, layer, cv::Size(w, h), 0, 0, cv::INTER_AREA);
      // Pixel u' of the small layer is centred on u = (u' + 0.5) rx - 0.5 of the full one.
      origin = full_origin + full_du * (0.5 * rx - 0.5) + full_dv * (0.5 * ry - 0.5);
      du = full_du * rx;
      dv = full_dv * ry;
    }
  }
  // The layer's outline in the image gives the box to fill.
  const double w = layer.cols, h = layer.rows;
  std::vector<Eigen::Vector3d> outline;
  constexpr int kEdge = 16;
  for (int k = 0; k <= kEdge; ++k) {
    const double f = static_cast<double>(k) / kEdge;
    outline.push_back(origin + du * (f * w) - dv * 0.5);
    outline.push_back(origin + du * (f * w) + dv * (h - 0.5));
    outline.push_back(origin + dv * (f * h) - du * 0.5);
    outline.push_back(origin + dv * (f * h) + du * (w - 0.5));
  }
  double x0 = 1e18, y0 = 1e18, x1 = -1e18, y1 = -1e18;
  for (const Eigen::Vector3d& p : outline) {
    const Eigen::Vector2d px = camera_.ProjectGround(p);
    if (!px.allFinite()) return;  // (partly) behind the camera: not drawn
    x0 = std::min(x0, px.x());
    y0 = std::min(y0, px.y());
    x1 = std::max(x1, px.x());
    y1 = std::max(y1, px.y());
  }
  const int bx0 = std::max(0, static_cast<int>(std::floor(x0)) - 1);
  const int by0 = std::max(0, static_cast<int>(std::floor(y0)) - 1);
  const int bx1 = std::min(canvas->cols - 1, static_cast<int>(std::ceil(x1)) + 1);
  const int by1 = std::min(canvas->rows - 1, static_cast<int>(std::ceil(y1)) + 1);
  if (bx1 < bx0 || by1 < by0) return;
  const int bw = bx1 - bx0 + 1, bh = by1 - by0 + 1;

  // Layer coordinates of the grid's image pixels: ray -> plane -> (u, v).
  const int g = options_.grid_step_px;
  const int gw = GridPoints(bw, g), gh = GridPoints(bh, g);
  std::vector<Eigen::Vector2d> pixels(static_cast<size_t>(gw) * gh);
  for (int gy = 0; gy < gh; ++gy) {
    for (int gx = 0; gx < gw; ++gx)
      pixels[gy * gw + gx] = Eigen::Vector2d(bx0 + gx * g, by0 + gy * g);
  }
  std::vector<Eigen::Vector3d> rays(pixels.size());
  camera_.UnprojectMany(pixels.data(), pixels.size(), rays.data());
  const Eigen::Matrix3d ground_from_cam = camera_.cam_from_ground().rotation.transpose();
  const Eigen::Vector3d normal = du.cross(dv);
  const double du2 = du.squaredNorm(), dv2 = dv.squaredNorm();
  std::vector<Eigen::Vector2f> grid(pixels.size());
  constexpr float kOutside = -1e6f;
  for (size_t i = 0; i < rays.size(); ++i) {
    grid[i] = Eigen::Vector2f(kOutside, kOutside);
    if (!rays[i].allFinite()) continue;
    const Eigen::Vector3d d = ground_from_cam * rays[i];
    const double denom = d.dot(normal);
    if (std::abs(denom) < 1e-15) continue;
    const double s = (origin - centre_in_ground_).dot(normal) / denom;
    if (s <= 0) continue;
    const Eigen::Vector3d rel = centre_in_ground_ + s * d - origin;
    grid[i] = Eigen::Vector2f(static_cast<float>(rel.dot(du) / du2),
                              static_cast<float>(rel.dot(dv) / dv2));
  }
  cv::Mat map;
  InterpolateGridMap(grid, g, cv::Size(bw, bh), kOutside, map);
  cv::Mat warped;
  cv::remap(layer, warped, map, cv::noArray(), cv::INTER_LINEAR, cv::BORDER_CONSTANT,
            cv::Scalar::all(0));
  // Premultiplied "over".
  for (int y = 0; y < bh; ++y) {
    const auto* src = warped.ptr<cv::Vec4f>(y);
    auto* dst = canvas->ptr<cv::Vec4f>(by0 + y) + bx0;
    for (int x = 0; x < bw; ++x) {
      const float keep = 1.0f - src[x][3] / 255.0f;
      if (keep >= 1.0f) continue;
      dst[x] = src[x] + dst[x] * keep;
    }
  }
}

cv::Mat SpriteRenderer::Render(const std::vector<PlacedSprite>& sprites) const {
  cv::Mat canvas = background_.empty()
                       ? cv::Mat(camera_.height(), camera_.width(), CV_32FC4, cv::Scalar::all(0))
                       : background_.clone();
  // Far sprites first (simple depth sorting, seed 000 §6).
  std::vector<size_t> order(sprites.size());
  std::iota(order.begin(), order.end(), 0);
  auto distance = [&](size_t i) {
    const Eigen::Vector3d p(sprites[i].ground_m.x(), sprites[i].ground_m.y(), 0.0);
    return (p - centre_in_ground_).norm();
  };
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t a, size_t b) { return distance(a) > distance(b); });
  const Eigen::Vector3d up(0, 0, 1);
  // A sprite's floor axes: right (its image's x) and away (its image's y on the floor: from the
  // camera for an upright sprite's shadow, backwards for a floor sprite).
  const auto floor_axes = [&](const PlacedSprite& s, Eigen::Vector3d* right,
                              Eigen::Vector3d* away) {
    if (s.kind == SpriteKind::kFloor) {  // its heading up, seen from above: its right to the right
      const Eigen::Vector2d ahead(std::cos(s.heading_rad), std::sin(s.heading_rad));
      *right = Eigen::Vector3d(ahead.y(), -ahead.x(), 0.0);
      *away = Eigen::Vector3d(-ahead.x(), -ahead.y(), 0.0);
      return;
    }
    const Eigen::Vector2d toward = TowardCamera(s.ground_m);  // seen from the camera
    *right = Eigen::Vector3d(-toward.y(), toward.x(), 0.0);
    *away = Eigen::Vector3d(-toward.x(), -toward.y(), 0.0);
  };
  for (const PlacedSprite& s : sprites) {
    const bool floor = s.kind == SpriteKind::kFloor;
    const double angle = ViewAngleDeg(s.ground_m);
    if (floor ? angle >= options_.min_floor_view_deg : angle <= options_.max_upright_view_deg)
      continue;
    const std::string where = std::string(floor ? "floor" : "upright") + " sprite at (" +
                              OptionProblems::Num(s.ground_m.x()) + ", " +
                              OptionProblems::Num(s.ground_m.y()) + ")";
    const std::string seen = "the virtual camera sees it from " +
                             OptionProblems::Num(std::round(angle)) + " degrees above the floor, ";
    if (floor) {
      throw InputError(where, seen + "shallower than " +
                                  OptionProblems::Num(options_.min_floor_view_deg) +
                                  ": a subject filmed from above looks true only from above "
                                  "(render from a camera looking down at it)");
    }
    throw InputError(where, seen + "steeper than " +
                                OptionProblems::Num(options_.max_upright_view_deg) +
                                ": a billboard filmed from the side is a sliver from above "
                                "(render from a camera that looks across the floor, or film "
                                "the subject from above for floor sprites)");
  }
  if (options_.shadows) {
    for (size_t i : order) {
      const PlacedSprite& s = sprites[i];
      if (s.pixels == nullptr || s.pixels->shadow.empty() || !(s.px_per_m > 0)) continue;
      if (cv::countNonZero(s.pixels->shadow) == 0) continue;
      Eigen::Vector3d right, away;
      floor_axes(s, &right, &away);
      const Eigen::Vector3d p(s.ground_m.x(), s.ground_m.y(), 0.0);
      const double cu = (s.pixels->shadow.cols - 1) / 2.0, cv_ = (s.pixels->shadow.rows - 1) / 2.0;
      const Eigen::Vector3d origin = p - right * (cu / s.px_per_m) - away * (cv_ / s.px_per_m);
      DrawPlane(ShadowLayer(s.pixels->shadow, options_.shadow_opacity), origin, right / s.px_per_m,
                away / s.px_per_m, &canvas);
    }
  }
  // Floor sprites lie on the floor, under every upright one.
  for (const bool floor : {true, false}) {
    for (size_t i : order) {
      const PlacedSprite& s = sprites[i];
      if ((s.kind == SpriteKind::kFloor) != floor) continue;
      if (s.pixels == nullptr || s.pixels->bgra.empty() || !(s.px_per_m > 0)) continue;
      Eigen::Vector3d right, away;
      floor_axes(s, &right, &away);
      const Eigen::Vector3d p(s.ground_m.x(), s.ground_m.y(), 0.0);
      // Billboard pixel (u, v) = p + right (u - a_u) / s + up (a_v - v) / s (the rectifier's);
      // a floor sprite's: p + right (u - a_u) / s + away (v - a_v) / s.
      const Eigen::Vector3d dv = floor ? away : Eigen::Vector3d(-up);
      const Eigen::Vector3d origin =
          p - right * (s.anchor_px.x() / s.px_per_m) - dv * (s.anchor_px.y() / s.px_per_m);
      DrawPlane(Premultiply(s.pixels->bgra), origin, right / s.px_per_m, dv / s.px_per_m, &canvas);
    }
  }
  cv::Mat out(canvas.size(), CV_8UC4);
  for (int y = 0; y < canvas.rows; ++y) {
    const auto* in = canvas.ptr<cv::Vec4f>(y);
    auto* o = out.ptr<cv::Vec4b>(y);
    for (int x = 0; x < canvas.cols; ++x) {
      const float a = in[x][3];
      if (a <= 0.0f) {
        o[x] = cv::Vec4b(0, 0, 0, 0);
        continue;
      }
      const float k = 255.0f / a;
      o[x] = cv::Vec4b(cv::saturate_cast<uint8_t>(in[x][0] * k),
                       cv::saturate_cast<uint8_t>(in[x][1] * k),
                       cv::saturate_cast<uint8_t>(in[x][2] * k), cv::saturate_cast<uint8_t>(a));
    }
  }
  return out;
}

}  // namespace ss
