#pragma once
// A bank whose differences are known by hand, for the judge's tests. Three clips of 10 frames
// on 20x20 opaque billboards (contact point at the bottom centre), frame m showing a one-pixel
// column at x = m:
//   A: black with a white column, walking +x at 0.3 m/s;
//   B: white with a black column, walking +y;
//   C: A's pixels again, standing; frames 0-4 tagged "still".
// Consecutive frames differ in two columns of 20 pixels, each (|dR|+|dG|+|dB|)/(4*255) = 0.75:
// every clip step is 30 px, so the bank's median step is 30 px. A's frame m against B's frame
// k != m differs in the 18 other columns: 360 * 0.75 = 270 px; against B's frame m, 300 px.
#include <cstdint>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "core/bank.h"

namespace ss::testing {

struct ColumnBank {
  static constexpr int kFrames = 10;
  static constexpr int kSize = 20;
  static constexpr double kMedianStep_px = 30.0;
  std::vector<int64_t> a, b, c;  // sprite ids by frame

  static SpritePixels Pixels(bool white_ground, int column) {
    const uint8_t ground = white_ground ? 255 : 0;
    SpritePixels p;
    p.bgra = cv::Mat(kSize, kSize, CV_8UC4, cv::Scalar(ground, ground, ground, 255));
    p.bgra.col(column).setTo(cv::Scalar(255 - ground, 255 - ground, 255 - ground, 255));
    p.shadow = cv::Mat(kSize, kSize, CV_8UC1, cv::Scalar(0));
    return p;
  }

  static ColumnBank Write(const std::string& path) {
    ColumnBank out;
    BankWriter bank(path);
    const int64_t session =
        bank.AddSession({0, "test@columns", "columns", "2026-01-01T00:00:00Z", "test"});
    const int64_t camera = bank.AddCamera(session, {0, 0, "cam0", "", 640, 480});
    auto clip = [&](int track, bool white, double vx, double vy) {
      ClipRecord c;
      c.camera_id = camera;
      c.track_id = track;
      c.first_frame = 100 * track;
      c.last_frame = 100 * track + kFrames - 1;
      c.complete = true;
      std::vector<SpriteRecord> sprites;
      for (int m = 0; m < kFrames; ++m) {
        SpriteRecord s;
        s.frame = 100 * track + m;
        s.timestamp_ns = s.frame * 1'000'000'000LL / 30;
        s.velocity_x_m_s = vx;
        s.velocity_y_m_s = vy;
        s.area_px = kSize * kSize;
        s.bbox_in_image = cv::Rect(10, 10, kSize, kSize);
        s.billboard_width_px = kSize;
        s.billboard_height_px = kSize;
        s.px_per_m = 100.0;
        s.anchor_x_px = kSize / 2.0;
        s.anchor_y_px = kSize - 1.0;
        s.pixels = Pixels(white, m);
        sprites.push_back(std::move(s));
      }
      return bank.AppendClipBatch(c, sprites).sprite_ids;
    };
    out.a = clip(1, false, 0.3, 0.0);
    out.b = clip(2, true, 0.0, 0.3);
    out.c = clip(3, false, 0.0, 0.0);
    bank.Tag({out.c.begin(), out.c.begin() + 5}, "still");
    return out;
  }
};

}  // namespace ss::testing
