#include "synth/renderer.h"

#include <algorithm>
#include <array>
#include <cmath>

#include <Eigen/Dense>
#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "synth/random.h"

namespace ss::synth {
namespace {

inline uint8_t ToByte(double v) {
  return static_cast<uint8_t>(std::clamp(std::lround(v), 0L, 255L));
}

cv::Rect Clip(cv::Rect r, int width, int height) { return r & cv::Rect(0, 0, width, height); }

// Pixel box of the projections of `points`; the whole image when one is behind the camera.
cv::Rect ProjectedBox(const SynthCamera& cam, const std::vector<Eigen::Vector3d>& points,
                      double margin) {
  double x0 = 1e30, y0 = 1e30, x1 = -1e30, y1 = -1e30;
  for (const auto& p : points) {
    const Eigen::Vector2d px = cam.ProjectGround(p);
    if (!std::isfinite(px.x())) return {0, 0, cam.width, cam.height};
    x0 = std::min(x0, px.x());
    y0 = std::min(y0, px.y());
    x1 = std::max(x1, px.x());
    y1 = std::max(y1, px.y());
  }
  x0 = std::max(-1.0, x0 - margin);
  y0 = std::max(-1.0, y0 - margin);
  x1 = std::min(cam.width + 1.0, x1 + margin);
  y1 = std::min(cam.height + 1.0, y1 + margin);
  if (x1 < x0 || y1 < y0) return {};
  const int ix0 = static_cast<int>(std::floor(x0)), iy0 = static_cast<int>(std::floor(y0));
  return Clip(cv::Rect(ix0, iy0, static_cast<int>(std::ceil(x1)) - ix0 + 1,
                       static_cast<int>(std::ceil(y1)) - iy0 + 1),
              cam.width, cam.height);
}

MatteLayer TightLayer(int subject, const cv::Mat& full, cv::Point offset) {
  MatteLayer layer;
  layer.subject = subject;
  if (full.empty()) return layer;
  std::vector<cv::Point> nz;
  cv::findNonZero(full, nz);
  if (nz.empty()) return layer;
  const cv::Rect r = cv::boundingRect(nz);
  layer.values = full(r).clone();
  layer.box = r + offset;
  return layer;
}

}  // namespace

int SliceOf(int subsample, int slices) {
  if (slices <= 1) return 0;
  const int i = subsample % 4, j = subsample / 4;
  return (i + 2 * j + (j % 2) * 2) % 4 % slices;
}

CameraRenderer::CameraRenderer(const SynthCamera& camera, const Studio& studio)
    : camera_(camera), studio_(&studio), eye_(camera.CentreInGround()) {
  const int w = camera_.width, h = camera_.height;
  if (w <= 0 || h <= 0) throw InputError("size", "image size must be positive");
  lighting_.bounce = studio.FloorBounce();
  lighting_.scale = studio.subject_scale;
  // Rays through the pixel corners: corner (i, j) is at image point (i - 0.5, j - 0.5).
  const Eigen::Matrix3d ground_from_cam = camera_.cam_from_ground.rotation.transpose();
  corner_rays_.resize(static_cast<size_t>(w + 1) * (h + 1) * 3);
  for (int j = 0; j <= h; ++j) {
    for (int i = 0; i <= w; ++i) {
      const Eigen::Vector3d d = ground_from_cam * camera_.lens.Unproject({i - 0.5, j - 0.5});
      float* out = &corner_rays_[(static_cast<size_t>(j) * (w + 1) + i) * 3];
      out[0] = static_cast<float>(d.x());
      out[1] = static_cast<float>(d.y());
      out[2] = static_cast<float>(d.z());
    }
  }
  for (const Quad& q : studio.quads) {
    for (int k = 0; k < 3; ++k) quad_n_.push_back(static_cast<float>(q.normal[k]));
    quad_k_.push_back(static_cast<float>(q.normal.dot(q.origin - eye_)));
  }
  // Vignetting: radial fall-off around the principal point.
  vignette_.resize(static_cast<size_t>(w) * h);
  const double cx = camera_.lens.cx(), cy = camera_.lens.cy();
  const double r_corner = std::hypot(std::max(cx, w - cx), std::max(cy, h - cy));
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const double r = std::hypot(x - cx, y - cy) / r_corner;
      vignette_[y * w + x] =
          static_cast<float>(1.0 - camera_.vignetting * (0.7 * r * r + 0.3 * r * r * r * r));
    }
  }
  // The clean plate, 2 x 2 samples per pixel.
  plate_.create(h, w, CV_8UC3);
  bg_point_.resize(static_cast<size_t>(w) * h);
  bg_surface_.resize(static_cast<size_t>(w) * h);
  bg_quad_.resize(static_cast<size_t>(w) * h);
  std::vector<uint8_t> edge(static_cast<size_t>(w) * h, 0);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const size_t idx = static_cast<size_t>(y) * w + x;
      const Eigen::Vector3f c = RayAt(static_cast<float>(x), static_cast<float>(y));
      const BackgroundHit centre = studio.Trace(eye_, c.cast<double>());
      bg_point_[idx] = centre.point.cast<float>();
      bg_surface_[idx] = static_cast<uint8_t>(centre.surface);
      bg_quad_[idx] = static_cast<int16_t>(centre.quad);
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      for (int s = 0; s < 4; ++s) {
        const float ox = (s % 2) ? 0.25f : -0.25f, oy = (s / 2) ? 0.25f : -0.25f;
        const Eigen::Vector3f d = RayAt(x + ox, y + oy);
        const BackgroundHit hit = studio.Trace(eye_, d.cast<double>());
        if (hit.quad != centre.quad) edge[idx] = 1;
        sum += studio.Radiance(hit);
      }
      sum *= 0.25 * vignette_[idx];
      cv::Vec3b& px = plate_.at<cv::Vec3b>(y, x);
      for (int k = 0; k < 3; ++k) px[k] = ToByte(sum[k] * camera_.gain[k]);
    }
  }
  bg_edge_.assign(static_cast<size_t>(w) * h, 0);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      if (!edge[static_cast<size_t>(y) * w + x]) continue;
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const int xx = x + dx, yy = y + dy;
          if (xx >= 0 && yy >= 0 && xx < w && yy < h)
            bg_edge_[static_cast<size_t>(yy) * w + xx] = 1;
        }
      }
    }
  }
}

Eigen::Vector3f CameraRenderer::RayAt(float x, float y) const {
  const int w = camera_.width, h = camera_.height;
  const float gx = x + 0.5f, gy = y + 0.5f;
  const int i = std::clamp(static_cast<int>(std::floor(gx)), 0, w - 1);
  const int j = std::clamp(static_cast<int>(std::floor(gy)), 0, h - 1);
  const float fx = gx - i, fy = gy - j;
  const float* r00 = &corner_rays_[(static_cast<size_t>(j) * (w + 1) + i) * 3];
  const float* r10 = r00 + 3;
  const float* r01 = r00 + (w + 1) * 3;
  const float* r11 = r01 + 3;
  Eigen::Vector3f d;
  for (int k = 0; k < 3; ++k) {
    d[k] = (1 - fy) * ((1 - fx) * r00[k] + fx * r10[k]) + fy * ((1 - fx) * r01[k] + fx * r11[k]);
  }
  return d.normalized();
}

float CameraRenderer::BackgroundDepth(int x, int y, const float d[3]) const {
  const size_t idx = static_cast<size_t>(y) * camera_.width + x;
  if (bg_edge_[idx]) {
    return static_cast<float>(studio_->Trace(eye_, Eigen::Vector3d(d[0], d[1], d[2])).t);
  }
  const int q = bg_quad_[idx];
  const float* n = &quad_n_[q * 3];
  return quad_k_[q] / (n[0] * d[0] + n[1] * d[1] + n[2] * d[2]);
}

void CameraRenderer::Render(const FrameScene& scene, CameraImage* out) const {
  plate_.copyTo(out->bgr);
  out->alpha.assign(scene.subjects, MatteLayer{});
  for (int k = 0; k < scene.subjects; ++k) out->alpha[k].subject = k;
  out->shadow = MatteLayer{};
  out->visible_px.assign(scene.subjects, 0.0);
  out->unoccluded_px.assign(scene.subjects, 0.0);
  DrawShadows(scene, out);
  DrawBoards(scene, out);
  DrawSubjects(scene, out);
}

// ---------------------------------------------------------------------------
// Contact shadows: each primitive darkens the background below it, by its
// footprint (vertical projection), softer and weaker the higher it floats.

void CameraRenderer::DrawShadows(const FrameScene& scene, CameraImage* out) const {
  struct Caster {
    bool ellipse = true;
    Eigen::Vector2d c, a, b;
    Eigen::Matrix2d q_inv;
    double r_min = 0, radius = 0, z_bottom = 0, z_top = 0;
    cv::Rect box;
  };
  const double scale = studio_->subject_scale;
  const double strength = 0.55, h0 = 0.6 * scale, w0 = 0.05 * scale;
  std::vector<Caster> casters;
  cv::Rect all;
  for (const Primitive& p : scene.primitives) {
    if (p.slice != 0) continue;
    Caster c;
    c.z_bottom = std::max(0.0, p.LowestZ());
    c.z_top = p.HighestZ();
    Eigen::Vector2d lo, hi;
    if (p.shape == Shape::kEllipsoid) {
      const Eigen::Matrix2d q = (p.axes * p.axes.transpose()).topLeftCorner<2, 2>();
      c.c = p.centre.head<2>();
      c.q_inv = q.inverse();
      c.r_min = std::sqrt(std::max(
          1e-12, Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(q).eigenvalues().minCoeff()));
      const Eigen::Vector2d ext(std::sqrt(q(0, 0)), std::sqrt(q(1, 1)));
      lo = c.c - ext;
      hi = c.c + ext;
    } else {
      c.ellipse = false;
      c.a = p.a.head<2>();
      c.b = p.b.head<2>();
      c.radius = p.radius;
      lo = c.a.cwiseMin(c.b).array() - p.radius;
      hi = c.a.cwiseMax(c.b).array() + p.radius;
    }
    const double reach = 4.0 * (w0 + 0.35 * c.z_bottom);
    if (c.z_bottom > 3.0 * h0) continue;  // too high to darken anything visibly
    std::vector<Eigen::Vector3d> corners;
    for (double x : {lo.x() - reach, hi.x() + reach}) {
      for (double y : {lo.y() - reach, hi.y() + reach}) {
        for (double z : {0.0, c.z_top + 2 * w0}) corners.emplace_back(x, y, z);
      }
    }
    c.box = ProjectedBox(camera_, corners, 2.0);
    if (c.box.empty()) continue;
    all |= c.box;
    casters.push_back(c);
  }
  if (casters.empty() || all.empty()) return;
  cv::Mat shade(all.size(), CV_32F, cv::Scalar(1.0f));
  for (const Caster& c : casters) {
    for (int y = c.box.y; y < c.box.y + c.box.height; ++y) {
      float* row = shade.ptr<float>(y - all.y);
      for (int x = c.box.x; x < c.box.x + c.box.width; ++x) {
        const Eigen::Vector3f pf = bg_point_[static_cast<size_t>(y) * camera_.width + x];
        const Eigen::Vector2d p(pf.x(), pf.y());
        const double pz = pf.z();
        double sd = 0;
        if (c.ellipse) {
          const Eigen::Vector2d rel = p - c.c;
          const double dn = std::sqrt(rel.dot(c.q_inv * rel));
          sd = dn >= 1.0 ? rel.norm() * (1.0 - 1.0 / dn) : (dn - 1.0) * c.r_min;
        } else {
          const Eigen::Vector2d ab = c.b - c.a;
          const double s = ab.squaredNorm() > 1e-18
                               ? std::clamp((p - c.a).dot(ab) / ab.squaredNorm(), 0.0, 1.0)
                               : 0.0;
          sd = (p - (c.a + s * ab)).norm() - c.radius;
        }
        const double hz = std::max(0.0, c.z_bottom - pz);
        const double w = w0 + 0.35 * hz;
        double dark = strength * std::exp(-hz / h0) / (1.0 + std::exp(2.5 * sd / w));
        if (pz > c.z_top) dark *= std::exp(-(pz - c.z_top) / w0);
        row[x - all.x] *= static_cast<float>(1.0 - dark);
      }
    }
  }
  cv::Mat matte(all.size(), CV_8U, cv::Scalar(0));
  for (int y = 0; y < all.height; ++y) {
    const float* s = shade.ptr<float>(y);
    uint8_t* m = matte.ptr<uint8_t>(y);
    cv::Vec3b* px = out->bgr.ptr<cv::Vec3b>(y + all.y) + all.x;
    for (int x = 0; x < all.width; ++x) {
      const double occlusion = std::min(0.75, 1.0 - static_cast<double>(s[x]));
      const uint8_t q = ToByte(255.0 * occlusion);
      m[x] = q;
      if (q == 0) continue;
      const double keep = 1.0 - q / 255.0;
      for (int k = 0; k < 3; ++k) px[x][k] = ToByte(px[x][k] * keep);
    }
  }
  out->shadow = TightLayer(-1, matte, all.tl());
}

// ---------------------------------------------------------------------------
// Calibration boards: planar, printed black/white, box-filtered where a pixel
// straddles an edge of the print.

void CameraRenderer::DrawBoards(const FrameScene& scene, CameraImage* out) const {
  const int w = camera_.width;
  for (const BoardInstance& board : scene.boards) {
    const BoardSpec& spec = board.texture->spec();
    const Eigen::Matrix3d r = board.ground_from_board.rotation;
    const Eigen::Vector3d eye_b = r.transpose() * (eye_ - board.ground_from_board.translation);
    if (std::abs(eye_b.z()) < 1e-6) continue;
    const bool front = eye_b.z() < 0;  // the print faces the board's -z
    const Eigen::Vector3d facing = front ? Eigen::Vector3d(-r.col(2)) : Eigen::Vector3d(r.col(2));
    const double e = 0.3 + 0.8 * (0.5 + 0.5 * facing.z());
    const Eigen::Vector3d white = 255.0 * e * Eigen::Vector3d(0.80, 0.82, 0.83);
    const Eigen::Vector3d black = 255.0 * e * Eigen::Vector3d(0.05, 0.05, 0.055);
    const Eigen::Vector3d back = 255.0 * e * Eigen::Vector3d(0.30, 0.42, 0.52);
    const double m = spec.margin_m;
    std::vector<Eigen::Vector3d> corners;
    for (double x : {-m, spec.width_m() + m}) {
      for (double y : {-m, spec.height_m() + m})
        corners.push_back(board.ground_from_board * Eigen::Vector3d(x, y, 0));
    }
    const cv::Rect box = ProjectedBox(camera_, corners, 3.0);
    const Eigen::Matrix3f rt = r.transpose().cast<float>();
    const Eigen::Vector3f eb = eye_b.cast<float>();
    // Texel seen along unit direction d: 0 black, 1 white, 2 back, -1 none.
    auto sample = [&](int x, int y, const Eigen::Vector3f& d) -> int {
      const Eigen::Vector3f db = rt * d;
      if (std::abs(db.z()) < 1e-9f) return -1;
      const float t = -eb.z() / db.z();
      if (!(t > 0)) return -1;
      const float tbg = BackgroundDepth(x, y, d.data());
      if (t > tbg * (1.0f + 2e-5f) + 1e-6f) return -1;
      const Eigen::Vector3f pb = eb + t * db;
      const int v = board.texture->Sample(pb.x(), pb.y());
      if (v < 0) return -1;
      return front ? v : 2;
    };
    auto colour = [&](int v) -> const Eigen::Vector3d& {
      return v == 0 ? black : (v == 1 ? white : back);
    };
    for (int y = box.y; y < box.y + box.height; ++y) {
      for (int x = box.x; x < box.x + box.width; ++x) {
        const float taps[5][2] = {
            {0.02f, 0.02f}, {0.98f, 0.02f}, {0.02f, 0.98f}, {0.98f, 0.98f}, {0.5f, 0.5f}};
        int v0 = -2;
        bool uniform = true;
        for (const auto& tap : taps) {
          const int v = sample(x, y, RayAt(x - 0.5f + tap[0], y - 0.5f + tap[1]));
          if (v0 == -2) v0 = v;
          if (v != v0) {
            uniform = false;
            break;
          }
        }
        if (uniform && v0 == -1) continue;
        Eigen::Vector3d sum = Eigen::Vector3d::Zero();
        double coverage = 0;
        if (uniform) {
          sum = colour(v0);
          coverage = 1.0;
        } else {
          // 16 samples on distinct rows and columns (n-rooks: x = s, y = 7 s
          // mod 16, in 16ths). On a 4 x 4 grid an edge nearly along a pixel
          // axis crosses a whole row of samples at once, coverage moves in
          // quarter steps and each board corner lands up to ~0.1 px off, a
          // fixed pattern that tilted the floor board's pose by ~0.1 deg.
          constexpr int kBoardSamples = kSubsamples;
          static_assert(kBoardSamples == 16, "the n-rooks pattern below is for 16 samples");
          for (int s = 0; s < kBoardSamples; ++s) {
            const float ox = (s + 0.5f) / kBoardSamples,
                        oy = ((s * 7) % kBoardSamples + 0.5f) / kBoardSamples;
            const int v = sample(x, y, RayAt(x - 0.5f + ox, y - 0.5f + oy));
            if (v < 0) continue;
            sum += colour(v) / kBoardSamples;
            coverage += 1.0 / kBoardSamples;
          }
        }
        const float vig = vignette_[static_cast<size_t>(y) * w + x];
        cv::Vec3b& px = out->bgr.at<cv::Vec3b>(y, x);
        for (int k = 0; k < 3; ++k)
          px[k] = ToByte(sum[k] * camera_.gain[k] * vig + (1.0 - coverage) * px[k]);
      }
    }
  }
}

// ---------------------------------------------------------------------------
// Subjects: per pixel, the primitives whose boxes hold it are intersected with
// the pixel's rays. Five taps decide whether the pixel is uniform (one
// primitive, or none, everywhere); otherwise 16 subsamples give coverage.

void CameraRenderer::DrawSubjects(const FrameScene& scene, CameraImage* out) const {
  std::vector<PreparedPrimitive> prepared;
  prepared.reserve(scene.primitives.size());
  cv::Rect all;
  for (size_t i = 0; i < scene.primitives.size(); ++i) {
    PreparedPrimitive p;
    if (!Prepare(scene.primitives[i], static_cast<int>(i), camera_, &p)) continue;
    prepared.push_back(p);
    all |= cv::Rect(p.x0, p.y0, p.x1 - p.x0 + 1, p.y1 - p.y0 + 1);
  }
  if (prepared.empty()) return;
  if (scene.subjects > 64) throw InputError("subjects", "at most 64 subjects can be rendered");
  const int w = camera_.width;
  const int slices = std::max(1, scene.slices);
  std::vector<cv::Mat> alpha(scene.subjects);
  for (auto& a : alpha) a = cv::Mat(all.size(), CV_8U, cv::Scalar(0));
  const float eye_z = static_cast<float>(eye_.z());

  struct Sample {
    int prim = -1;  // index into `prepared`, -1 background
    float t = 0;
    uint64_t seen = 0;  // subjects hit at all (above the floor), occluded or not
  };
  std::vector<int> active, cand;
  auto trace = [&](int x, int y, const Eigen::Vector3f& d, int slice) {
    Sample s;
    float best = BackgroundDepth(x, y, d.data());
    for (int ci : cand) {
      const PreparedPrimitive& p = prepared[ci];
      if (p.slice != slice) continue;
      const float t = p.Intersect(d.data());
      if (t <= 0.f || eye_z + t * d.z() < -1e-4f) continue;
      s.seen |= uint64_t{1} << p.subject;
      if (t < best) {
        best = t;
        s.prim = ci;
      }
    }
    s.t = best;
    return s;
  };
  auto shade = [&](int ci, const Eigen::Vector3d& point, const Eigen::Vector3d& d) {
    return Shade(scene.primitives[prepared[ci].index], point, d, lighting_);
  };

  for (int y = all.y; y < all.y + all.height; ++y) {
    active.clear();
    for (size_t i = 0; i < prepared.size(); ++i) {
      if (prepared[i].y0 <= y && y <= prepared[i].y1) active.push_back(static_cast<int>(i));
    }
    if (active.empty()) continue;
    for (int x = all.x; x < all.x + all.width; ++x) {
      cand.clear();
      for (int i : active) {
        if (prepared[i].x0 <= x && x <= prepared[i].x1) cand.push_back(i);
      }
      if (cand.empty()) continue;
      const float vig = vignette_[static_cast<size_t>(y) * w + x];
      cv::Vec3b& px = out->bgr.at<cv::Vec3b>(y, x);
      // Uniform pixels (no motion blur only).
      if (slices == 1) {
        const float taps[5][2] = {
            {0.02f, 0.02f}, {0.98f, 0.02f}, {0.02f, 0.98f}, {0.98f, 0.98f}, {0.5f, 0.5f}};
        Sample centre;
        bool uniform = true;
        int first = -2;
        for (int k = 0; k < 5 && uniform; ++k) {
          const Sample s = trace(x, y, RayAt(x - 0.5f + taps[k][0], y - 0.5f + taps[k][1]), 0);
          const uint64_t own = s.prim >= 0 ? (uint64_t{1} << prepared[s.prim].subject) : 0;
          if (s.seen & ~own) uniform = false;  // something hidden behind: take subsamples
          if (first == -2) first = s.prim;
          if (s.prim != first) uniform = false;
          if (k == 4) centre = s;
        }
        if (uniform && first == -1) continue;
        if (uniform) {
          const PreparedPrimitive& p = prepared[first];
          const Eigen::Vector3d d =
              RayAt(static_cast<float>(x), static_cast<float>(y)).cast<double>();
          const Eigen::Vector3d c = shade(first, eye_ + static_cast<double>(centre.t) * d, d);
          for (int k = 0; k < 3; ++k) px[k] = ToByte(c[k] * camera_.gain[k] * vig);
          alpha[p.subject].at<uint8_t>(y - all.y, x - all.x) = 255;
          out->visible_px[p.subject] += 1.0;
          out->unoccluded_px[p.subject] += 1.0;
          continue;
        }
      }
      // Subsamples.
      struct Group {
        int prim;
        int count;
        Eigen::Vector3d point;
        Eigen::Vector3d dir;
      };
      std::array<Group, 16> groups;
      int n_groups = 0;
      std::array<int, 64> seen_count{};
      int covered = 0;
      for (int s = 0; s < kSubsamples; ++s) {
        const int column = s % 4, row = s / 4;  // a 4 x 4 grid
        const float ox = (static_cast<float>(column) + 0.5f) / 4.0f,
                    oy = (static_cast<float>(row) + 0.5f) / 4.0f;
        const Eigen::Vector3f d = RayAt(x - 0.5f + ox, y - 0.5f + oy);
        const Sample smp = trace(x, y, d, SliceOf(s, slices));
        for (uint64_t m = smp.seen; m; m &= m - 1) ++seen_count[__builtin_ctzll(m)];
        if (smp.prim < 0) continue;
        ++covered;
        const Eigen::Vector3d dd = d.cast<double>();
        const Eigen::Vector3d point = eye_ + static_cast<double>(smp.t) * dd;
        int g = 0;
        while (g < n_groups && groups[g].prim != smp.prim) ++g;
        if (g == n_groups)
          groups[n_groups++] = {smp.prim, 0, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
        groups[g].count += 1;
        groups[g].point += point;
        groups[g].dir += dd;
      }
      for (int k = 0; k < scene.subjects; ++k)
        out->unoccluded_px[k] += seen_count[k] / double(kSubsamples);
      if (covered == 0) continue;
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      std::array<int, 64> subject_count{};
      for (int g = 0; g < n_groups; ++g) {
        const Group& gr = groups[g];
        const Eigen::Vector3d c = shade(gr.prim, gr.point / gr.count, gr.dir.normalized());
        sum += c * (static_cast<double>(gr.count) / kSubsamples);
        subject_count[prepared[gr.prim].subject] += gr.count;
      }
      const double coverage = static_cast<double>(covered) / kSubsamples;
      for (int k = 0; k < 3; ++k)
        px[k] = ToByte(sum[k] * camera_.gain[k] * vig + (1.0 - coverage) * px[k]);
      for (int k = 0; k < scene.subjects; ++k) {
        if (subject_count[k] == 0) continue;
        alpha[k].at<uint8_t>(y - all.y, x - all.x) = ToByte(255.0 * subject_count[k] / kSubsamples);
        out->visible_px[k] += static_cast<double>(subject_count[k]) / kSubsamples;
      }
    }
  }
  for (int k = 0; k < scene.subjects; ++k) out->alpha[k] = TightLayer(k, alpha[k], all.tl());
}

// ---------------------------------------------------------------------------

Sensor::Sensor(uint64_t seed, int camera, double noise) : seed_(seed), camera_(camera) {
  Rng rng(StreamSeed(seed, "sensor-noise-table", static_cast<uint64_t>(camera)));
  table_.resize(1 << 18);
  for (float& v : table_) v = static_cast<float>(rng.Normal());
  for (int i = 0; i < 256; ++i) {
    // Read noise 1.1 DN plus shot noise (variance proportional to the signal).
    sigma_[i] = static_cast<float>(noise * std::sqrt(1.1 * 1.1 + 0.032 * i));
  }
}

std::vector<uint8_t> Sensor::Capture(const cv::Mat& bgr, PixelFormat format,
                                     uint64_t frame_index) const {
  const int w = bgr.cols, h = bgr.rows;
  Rng rng(StreamSeed(seed_, "sensor-frame", (static_cast<uint64_t>(camera_) << 40) ^ frame_index));
  const size_t table = table_.size();
  auto noisy = [&](uint8_t v, float n) {
    const float out = static_cast<float>(v) + n * sigma_[v] + 0.5f;
    return static_cast<uint8_t>(std::clamp(out, 0.0f, 255.0f));
  };
  std::vector<uint8_t> bytes;
  switch (format) {
    case PixelFormat::kBGR8:
    case PixelFormat::kRGB8: {
      bytes.resize(static_cast<size_t>(w) * h * 3);
      const bool swap = format == PixelFormat::kRGB8;
      for (int y = 0; y < h; ++y) {
        const float* n = &table_[rng.Bits() % (table - static_cast<size_t>(w) * 3)];
        const uint8_t* src = bgr.ptr<uint8_t>(y);
        uint8_t* dst = &bytes[static_cast<size_t>(y) * w * 3];
        for (int x = 0; x < w; ++x) {
          const uint8_t b = noisy(src[3 * x], n[3 * x]);
          const uint8_t g = noisy(src[3 * x + 1], n[3 * x + 1]);
          const uint8_t r = noisy(src[3 * x + 2], n[3 * x + 2]);
          dst[3 * x] = swap ? r : b;
          dst[3 * x + 1] = g;
          dst[3 * x + 2] = swap ? b : r;
        }
      }
      break;
    }
    case PixelFormat::kBayerRG8:
    case PixelFormat::kMono8: {
      bytes.resize(static_cast<size_t>(w) * h);
      const bool bayer = format == PixelFormat::kBayerRG8;
      for (int y = 0; y < h; ++y) {
        const float* n = &table_[rng.Bits() % (table - static_cast<size_t>(w))];
        const uint8_t* src = bgr.ptr<uint8_t>(y);
        uint8_t* dst = &bytes[static_cast<size_t>(y) * w];
        for (int x = 0; x < w; ++x) {
          uint8_t v = 0;
          if (bayer) {
            // RGGB: R at (even row, even column), B at (odd, odd), G elsewhere.
            const int channel = (y % 2 == 0) ? (x % 2 == 0 ? 2 : 1) : (x % 2 == 0 ? 1 : 0);
            v = src[3 * x + channel];
          } else {
            v = static_cast<uint8_t>(
                (src[3 * x] * 29 + src[3 * x + 1] * 150 + src[3 * x + 2] * 77 + 128) >> 8);
          }
          dst[x] = noisy(v, n[x]);
        }
      }
      break;
    }
    default:
      throw InputError("pixel-format",
                       "the synthetic camera delivers rgb8, bgr8, bayer_rg8 or mono8, not " +
                           PixelFormatName(format));
  }
  return bytes;
}

}  // namespace ss::synth
