#pragma once
// A synthetic sprite bank and virtual camera for the animate tests (until the live pipeline
// fills real banks): a "walker" with eight straight walking clips (headings 0°, 45°, ...),
// a standing clip tagged "standing", transitions between neighbouring headings, and small
// synthetic billboards (a coloured ellipse with a contact shadow).
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/imgproc.hpp>

#include "core/bank.h"
#include "core/camera_model.h"

namespace ss::testing {

struct WalkerBank {
  static constexpr int kClipFrames = 24;
  static constexpr int kStandFrames = 12;
  static constexpr double kSpeed_m_s = 1.5;  // 0.05 m per frame at 30 fps
  static constexpr double kFps = 30.0;
  static constexpr double kPxPerM = 400.0;
  static constexpr int kWidth = 41, kHeight = 81;  // 0.1 m x 0.2 m billboards

  // sprite_ids[c][m]: clip c (0..7 headings, 8 standing), frame m.
  std::vector<std::vector<int64_t>> sprite_ids;

  static SpritePixels Pixels(int clip) {
    SpritePixels p;
    p.bgra = cv::Mat(kHeight, kWidth, CV_8UC4, cv::Scalar(0, 0, 0, 0));
    const cv::Scalar colour(40 + 25 * clip, 200 - 20 * clip, 120, 255);
    cv::ellipse(p.bgra, {kWidth / 2, kHeight / 2}, {kWidth / 2 - 2, kHeight / 2 - 2}, 0, 0, 360,
                colour, cv::FILLED);
    p.shadow = cv::Mat(kHeight, kWidth, CV_8UC1, cv::Scalar(0));
    cv::ellipse(p.shadow, {kWidth / 2, kHeight / 2}, {12, 12}, 0, 0, 360, cv::Scalar(160),
                cv::FILLED);
    return p;
  }

  static WalkerBank Write(const std::string& path) {
    WalkerBank out;
    BankWriter bank(path);
    const int64_t session =
        bank.AddSession({0, "test@walker", "walker", "2026-01-01T00:00:00Z", "test"});
    const int64_t camera = bank.AddCamera(session, {0, 0, "cam0", "", 640, 480});
    for (int c = 0; c < 9; ++c) {
      const bool standing = c == 8;
      const int n = standing ? kStandFrames : kClipFrames;
      const double a = 2 * std::numbers::pi * c / 8;
      const Eigen::Vector2d v =
          standing ? Eigen::Vector2d(0, 0)
                   : Eigen::Vector2d(std::cos(a) * kSpeed_m_s, std::sin(a) * kSpeed_m_s);
      ClipRecord clip;
      clip.camera_id = camera;
      clip.track_id = c + 1;
      clip.first_frame = 1000 * c;
      clip.last_frame = 1000 * c + n - 1;
      clip.complete = true;
      std::vector<SpriteRecord> sprites;
      for (int m = 0; m < n; ++m) {
        SpriteRecord s;
        s.frame = 1000 * c + m;
        s.timestamp_ns = static_cast<int64_t>(std::llround(s.frame * 1e9 / kFps));
        s.ground_x_m = 0.0;
        s.ground_y_m = 0.0;
        s.velocity_x_m_s = v.x();
        s.velocity_y_m_s = v.y();
        s.mean_r = s.mean_g = s.mean_b = 100;
        s.area_px = 2000;
        s.eccentricity = 0.5;
        s.bbox_in_image = cv::Rect(10, 10, 20, 40);
        s.billboard_width_px = kWidth;
        s.billboard_height_px = kHeight;
        s.px_per_m = kPxPerM;
        s.anchor_x_px = (kWidth - 1) / 2.0;
        s.anchor_y_px = kHeight - 1.0;
        s.pixels = Pixels(c);
        sprites.push_back(std::move(s));
      }
      out.sprite_ids.push_back(bank.AppendClipBatch(clip, sprites).sprite_ids);
    }
    std::vector<TransitionRecord> t;
    auto add = [&](int c0, int m0, int c1, int m1, double cost) {
      t.push_back({out.sprite_ids[c0][m0], out.sprite_ids[c1][m1], cost / 2, cost});
    };
    for (int d = 0; d < 8; ++d) {
      add(d, kClipFrames - 1, d, 0, 0.05);  // each walk loops
      for (int m = 0; m + 1 < kClipFrames; m += 4) {
        add(d, m, (d + 1) % 8, m + 1, 0.3);
        add(d, m, (d + 7) % 8, m + 1, 0.3);
      }
      add(d, 12, 8, 0, 0.4);
      add(8, kStandFrames - 1, d, 0, 0.4);
    }
    add(8, kStandFrames - 1, 8, 0, 0.05);
    bank.UpsertTransitions(t);
    bank.Tag(out.sprite_ids[8], "standing");
    return out;
  }
};

// A pinhole camera at `centre_in_ground` looking at `target_in_ground` (image y down).
inline CameraModel LookAtCamera(int width, int height, double focal_px,
                                const Eigen::Vector3d& centre_in_ground,
                                const Eigen::Vector3d& target_in_ground) {
  const Eigen::Vector3d z = (target_in_ground - centre_in_ground).normalized();
  const Eigen::Vector3d x = z.cross(Eigen::Vector3d(0, 0, 1)).normalized();
  const Eigen::Vector3d y = z.cross(x);
  Rigid3 cam_from_ground;
  cam_from_ground.rotation.row(0) = x.transpose();
  cam_from_ground.rotation.row(1) = y.transpose();
  cam_from_ground.rotation.row(2) = z.transpose();
  cam_from_ground.translation = -(cam_from_ground.rotation * centre_in_ground);
  return CameraModel("LENSMODEL_PINHOLE",
                     {focal_px, focal_px, (width - 1) / 2.0, (height - 1) / 2.0}, width, height,
                     cam_from_ground);
}

}  // namespace ss::testing
