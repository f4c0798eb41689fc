#pragma once
// Frames with known truth for the keyer and extractor tests (and the key
// benchmark) until they switch to synth/'s studio. The floor is deliberately
// hard: green with low-frequency unevenness of brightness *and* tint,
// vignetting to half brightness in the corners, Gaussian noise; or a textured
// non-green carpet. Subjects are brown textured ellipses (plus optional thin
// bars: legs) with soft edges, green spill on their rim and a soft contact
// shadow under them. A keyer that only works on flat green fails these frames.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace ss::testing {

struct SceneBar {  // a thin straight part (a leg), axis from its centre
  cv::Point2d centre;
  double length = 0, width = 10, angle_deg = 90;  // 90: vertical
};

struct SceneSubject {
  cv::Point2d centre{320, 240};
  double rx = 60, ry = 40;  // ellipse radii, px; rx = 0: no ellipse (bars only)
  std::vector<SceneBar> bars;
  cv::Vec3d colour{40, 70, 125};  // BGR brown
  double texture = 0.25;          // relative brightness variation of the fur
  double spill = 70;              // green added within 4 px of the rim
  double shadow_depth = 0.45;     // darkening at the shadow's centre
};

struct SceneOptions {
  cv::Size size{640, 480};
  bool green = true;         // false: a textured blue-grey carpet
  double vignetting = 0.5;   // darkening in the corners
  double unevenness = 0.12;  // low-frequency brightness variation
  double tint = 1.0;         // low-frequency variation of the green's hue (0: flat green)
  double noise_sigma = 3.0;  // per channel, levels
  double edge_px = 2.0;      // width of the soft edge's alpha ramp
  uint64_t seed = 1;
};

struct SceneFrame {
  cv::Mat bgr;        // CV_8UC3
  cv::Mat alpha;      // CV_32F true alpha 0..1
  cv::Mat darkening;  // CV_32F true shadow darkening 0..1 (of the floor, everywhere)
  cv::Mat rim;        // CV_8U 255 on subject pixels (alpha 1) within 4 px of the edge: spill
  cv::Mat clean;      // CV_32FC3 the subject's own colour without spill (where alpha > 0)
};

class KeyScene {
 public:
  explicit KeyScene(SceneOptions options) : o_(options) {
    const int w = o_.size.width, h = o_.size.height;
    cv::RNG rng(o_.seed);
    floor_.create(o_.size, CV_32FC3);
    cv::Mat fine(o_.size, CV_32F), coarse(o_.size, CV_32F);
    if (!o_.green) {
      fine = BlurredNoise(rng, 1.5);
      coarse = BlurredNoise(rng, 10);
    }
    const double p[6] = {rng.uniform(0.0, 6.28), rng.uniform(0.0, 6.28), rng.uniform(0.0, 6.28),
                         rng.uniform(0.0, 6.28), rng.uniform(0.0, 6.28), rng.uniform(0.0, 6.28)};
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        const double u = static_cast<double>(x) / w, v = static_cast<double>(y) / h;
        const double r2 = ((u - 0.5) * (u - 0.5) + (v - 0.5) * (v - 0.5)) / 0.5;
        const double light =
            (1 - o_.vignetting * r2) *
            (1 + o_.unevenness *
                     (std::sin(6.28 * 1.3 * u + p[0]) + std::sin(6.28 * 0.9 * v + p[1])) / 2);
        cv::Vec3d c;
        if (o_.green) {
          const double t1 = std::sin(6.28 * (0.8 * u + 0.5 * v) + p[2]);
          const double t2 = std::sin(6.28 * (0.6 * u - 0.9 * v) + p[3]);
          c = {62 + o_.tint * 28 * t2, 168,
               55 + o_.tint * 42 * std::max(t1, 0.0) + o_.tint * 8 * t1};
        } else {
          const double t = 0.6 * fine.at<float>(y, x) + 0.4 * coarse.at<float>(y, x);
          const double s = std::sin(6.28 * 9 * u + p[4]) * std::sin(6.28 * 7 * v + p[5]);
          c = {150 + 45 * t + 10 * s, 128 + 40 * t + 10 * s, 105 + 35 * t + 8 * s};
        }
        floor_.at<cv::Vec3f>(y, x) = cv::Vec3f(c * light);
      }
    }
  }

  const SceneOptions& options() const { return o_; }

  // The empty enclosure, noise drawn for frame `index`.
  cv::Mat Empty(int index) const { return Render({}, index).bgr; }

  SceneFrame Render(const std::vector<SceneSubject>& subjects, int index) const {
    const int w = o_.size.width, h = o_.size.height;
    SceneFrame f;
    f.alpha = cv::Mat::zeros(o_.size, CV_32F);
    f.darkening = cv::Mat::zeros(o_.size, CV_32F);
    f.rim = cv::Mat::zeros(o_.size, CV_8U);
    cv::Mat colour(o_.size, CV_32FC3, cv::Scalar::all(0));
    f.clean = cv::Mat::zeros(o_.size, CV_32FC3);
    cv::RNG rng(o_.seed * 7919 + static_cast<uint64_t>(index) + 1);
    for (const SceneSubject& s : subjects) {
      const cv::Mat fur = BlurredNoise(rng, 2.5);
      const cv::Point2d sc(s.centre.x, s.centre.y + 0.85 * s.ry);
      const double sx = std::max(0.7 * s.rx, 6.0), sy = std::max(0.3 * s.ry, 4.0);
      for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
          const double dx = x - sc.x, dy = y - sc.y;
          const double dark =
              s.shadow_depth * std::exp(-(dx * dx / (2 * sx * sx) + dy * dy / (2 * sy * sy)));
          float& d = f.darkening.at<float>(y, x);
          d = static_cast<float>(1 - (1 - d) * (1 - dark));
          const double sd = SignedDistance(s, x, y);
          const double a = std::clamp(0.5 - sd / o_.edge_px, 0.0, 1.0);
          if (a <= 0) continue;
          cv::Vec3d c = s.colour * (1 + s.texture * fur.at<float>(y, x));
          const cv::Vec3d own = c;
          const double rim = std::clamp(1 + sd / 4, 0.0, 1.0);  // 1 at the edge, 0 from 4 px inside
          c[1] += s.spill * rim;
          if (a >= 1 && sd > -4) f.rim.at<uint8_t>(y, x) = 255;
          float& fa = f.alpha.at<float>(y, x);
          if (a > fa) {
            fa = static_cast<float>(a);
            colour.at<cv::Vec3f>(y, x) = cv::Vec3f(c);
            f.clean.at<cv::Vec3f>(y, x) = cv::Vec3f(own);
          }
        }
      }
    }
    cv::Mat noise(o_.size, CV_32FC3);
    rng.fill(noise, cv::RNG::NORMAL, 0, o_.noise_sigma);
    cv::Mat out(o_.size, CV_32FC3);
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        const float a = f.alpha.at<float>(y, x);
        const cv::Vec3f bg = floor_.at<cv::Vec3f>(y, x) * (1 - f.darkening.at<float>(y, x));
        out.at<cv::Vec3f>(y, x) =
            a * colour.at<cv::Vec3f>(y, x) + (1 - a) * bg + noise.at<cv::Vec3f>(y, x);
      }
    }
    out.convertTo(f.bgr, CV_8UC3);  // rounds and saturates
    return f;
  }

  // Where alpha falls through 1/2 at the bottom of an ellipse-only subject.
  static cv::Point2d LowestPoint(const SceneSubject& s) { return {s.centre.x, s.centre.y + s.ry}; }

 private:
  // Approximate signed distance to the subject's outline, px (negative inside).
  static double SignedDistance(const SceneSubject& s, double x, double y) {
    double best = 1e9;
    if (s.rx > 0) {
      const double u = (x - s.centre.x) / s.rx, v = (y - s.centre.y) / s.ry;
      const double rho = std::sqrt(u * u + v * v);
      if (rho < 1e-9) {
        best = -std::min(s.rx, s.ry);
      } else {
        const double gx = u / (s.rx * rho), gy = v / (s.ry * rho);  // gradient of rho
        best = (rho - 1) / std::sqrt(gx * gx + gy * gy);
      }
    }
    for (const SceneBar& b : s.bars) {
      const double a = b.angle_deg * CV_PI / 180;
      const double dx = x - b.centre.x, dy = y - b.centre.y;
      const double along = dx * std::cos(a) + dy * std::sin(a),
                   across = -dx * std::sin(a) + dy * std::cos(a);
      best =
          std::min(best, std::max(std::abs(along) - b.length / 2, std::abs(across) - b.width / 2));
    }
    return best;
  }

  // Smooth noise with unit-ish amplitude (std 0.5), clipped to [-1, 1].
  cv::Mat BlurredNoise(cv::RNG& rng, double sigma) const {
    cv::Mat n(o_.size, CV_32F);
    rng.fill(n, cv::RNG::NORMAL, 0, 1);
    cv::GaussianBlur(n, n, cv::Size(), sigma);
    cv::Scalar mean, sd;
    cv::meanStdDev(n, mean, sd);
    n = (n - mean[0]) * (0.5 / std::max(sd[0], 1e-9));
    return cv::min(cv::max(n, -1.0), 1.0);
  }

  SceneOptions o_;
  cv::Mat floor_;  // CV_32FC3, lit floor without noise or shadows
};

// Soft IoU of two alpha images (CV_32F 0..1 truth, CV_8U matte): sum min / sum max.
inline double SoftIoU(const cv::Mat& truth, const cv::Mat& alpha8) {
  cv::Mat a;
  alpha8.convertTo(a, CV_32F, 1.0 / 255);
  return cv::sum(cv::min(truth, a))[0] / std::max(cv::sum(cv::max(truth, a))[0], 1e-9);
}

// IoU of the two at alpha > 1/2.
inline double BinaryIoU(const cv::Mat& truth, const cv::Mat& alpha8) {
  cv::Mat t = truth > 0.5, a = alpha8 > 127;
  return static_cast<double>(cv::countNonZero(t & a)) / std::max(cv::countNonZero(t | a), 1);
}

}  // namespace ss::testing
