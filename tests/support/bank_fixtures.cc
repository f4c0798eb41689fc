#include "tests/support/bank_fixtures.h"

#include <sqlite3.h>

#include <random>

#include <gtest/gtest.h>

namespace ss::testing {

// A billboard with a soft elliptical matte, textured colour and a shadow blob.
SpritePixels MakePixels(int w, int h, uint32_t seed) {
  std::mt19937 rng(seed);
  SpritePixels p;
  p.bgra.create(h, w, CV_8UC4);
  p.shadow.create(h, w, CV_8UC1);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const double dx = (x - w / 2.0) / (w * 0.3), dy = (y - h / 2.0) / (h * 0.45);
      const double r = dx * dx + dy * dy;
      const auto a = static_cast<uint8_t>(r < 0.8 ? 255 : r < 1.0 ? (1.0 - r) * 1275 : 0);
      p.bgra.at<cv::Vec4b>(y, x) = {static_cast<uint8_t>(rng() % 256),
                                    static_cast<uint8_t>(x * 3 + seed), static_cast<uint8_t>(y * 2),
                                    a};
      p.shadow.at<uint8_t>(y, x) = static_cast<uint8_t>(y > h * 0.85 ? 100 + rng() % 50 : 0);
    }
  }
  return p;
}

// An original sprite with every field distinct and derived from (frame, track).
SpriteRecord MakeSprite(int64_t frame, int64_t track, int w, int h) {
  SpriteRecord s;
  s.frame = frame;
  s.timestamp_ns = 1'000'000'000 + frame * 16'666'667;
  s.ground_x_m = 0.25 + 0.01 * frame + track;
  s.ground_y_m = -1.5 + 0.002 * frame;
  s.velocity_x_m_s = 0.6 + 0.001 * frame;
  s.velocity_y_m_s = -0.2;
  s.mean_r = 120.5 + track;
  s.mean_g = 33.25;
  s.mean_b = 200.125 - frame % 7;
  s.area_px = 812.5 + frame;
  s.eccentricity = 0.4375;
  s.bbox_in_image = cv::Rect(100 + static_cast<int>(frame), 200, 40, 90);
  s.billboard_width_px = w;
  s.billboard_height_px = h;
  s.px_per_m = 200.0;
  s.anchor_x_px = w / 2.0 + 0.25;
  s.anchor_y_px = h - 1.5;
  s.pixels = MakePixels(w, h, static_cast<uint32_t>(frame * 31 + track));
  return s;
}

// The mirrored copy of `o`: velocity reflected across the billboard's vertical axis (here y).
SpriteRecord MakeMirror(const SpriteRecord& o) {
  SpriteRecord m = o;
  m.mirrored = true;
  m.velocity_x_m_s = -o.velocity_x_m_s;
  m.anchor_x_px = o.billboard_width_px - o.anchor_x_px;
  m.pixels = {};
  m.tags = {};
  return m;
}

// Originals and mirrors for frames [first, last] of one track.
std::vector<SpriteRecord> MakeBatch(int64_t first, int64_t last, int64_t track, bool mirrors) {
  std::vector<SpriteRecord> out;
  for (int64_t f = first; f <= last; ++f) {
    out.push_back(MakeSprite(f, track));
    if (mirrors) out.push_back(MakeMirror(out.back()));
  }
  return out;
}

Fixture Register(BankWriter& w) {
  Fixture f;
  f.session = w.AddSession(
      {0, "synth-a@2024-01-01T00:00:00Z", "synth-a", "2024-01-01T00:00:00Z", "/rec/synth-a"});
  f.camera = w.AddCamera(f.session, {0, 0, "cam0", "# mrcal model text\n", 1280, 720});
  return f;
}

ClipRecord Clip(int64_t camera, int64_t track, int64_t first, bool complete) {
  ClipRecord c;
  c.camera_id = camera;
  c.track_id = track;
  c.first_frame = first;
  c.complete = complete;
  return c;
}

int64_t RawCount(const std::string& path, const std::string& sql) {
  sqlite3* db = nullptr;
  sqlite3_open_v2(path.c_str(), &db, SQLITE_OPEN_READONLY, nullptr);
  sqlite3_stmt* stmt = nullptr;
  EXPECT_EQ(sqlite3_prepare_v2(db, sql.c_str(), -1, &stmt, nullptr), SQLITE_OK)
      << sqlite3_errmsg(db);
  const int64_t n = sqlite3_step(stmt) == SQLITE_ROW ? sqlite3_column_int64(stmt, 0) : -1;
  sqlite3_finalize(stmt);
  sqlite3_close(db);
  return n;
}

void RawExec(const std::string& path, const std::string& sql) {
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(path.c_str(), &db), SQLITE_OK);
  char* error = nullptr;
  EXPECT_EQ(sqlite3_exec(db, sql.c_str(), nullptr, nullptr, &error), SQLITE_OK)
      << (error ? error : "");
  sqlite3_free(error);
  sqlite3_close(db);
}

bool SameMat(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() && cv::norm(a, b, cv::NORM_INF) == 0;
}

// Writes a small sound bank and returns the id of one original sprite.
int64_t SmallBank(const std::string& path) {
  BankWriter w(path);
  const Fixture fx = Register(w);
  const auto r = w.AppendClipBatch(Clip(fx.camera, 1, 0, true), MakeBatch(0, 5, 1));
  w.AppendClipBatch(Clip(fx.camera, 2, 0, false), MakeBatch(0, 1, 2));
  return r.sprite_ids[0];
}

}  // namespace ss::testing
