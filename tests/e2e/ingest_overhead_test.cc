// Issue 38 end to end: an animal filmed from above (`synth --view overhead`) through
// `spritestation ingest`. The camera films its floor from above, so every sprite is stored as a
// floor sprite, none refused as view_too_steep; each lies where the animal is and faces the way
// it faces (truth/subjects.csv), head first across the whole clip, batches and all.
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/bank.h"
#include "tests/support/test_support.h"
#include "tests/synth/synth_csv.h"

namespace ss {
namespace {

using testing::JsonInOutput;
using testing::Num;
using testing::ReadCsv;
using testing::RunSpritestation;
using testing::ScratchDir;

double MedianOf(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

TEST(IngestOverhead, AnAnimalFilmedFromAboveIsStoredAsFloorSpritesFacingItsWay) {
  ScratchDir dir;
  const std::string session = dir / "session", bank = dir / "overhead.ssbank";
  auto r = RunSpritestation("synth --out " + session +
                            " --kind animal --view overhead --seconds 8 --size 480x360 "
                            "--cameras 1 --seed 11 --no-mattes");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = RunSpritestation("ingest " + session + " --bank " + bank + " --json --no-transitions");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("films its floor from above"), std::string::npos) << r.output;
  const nlohmann::json j = JsonInOutput(r.output);
  EXPECT_EQ(j["discards"]["view_too_steep"].get<int>(), 0) << r.output;
  ASSERT_GE(j["sprites_kept"].get<int>(), 150) << r.output;

  std::map<int64_t, std::map<std::string, std::string>> truth;  // by frame
  for (const auto& row : ReadCsv(session + "/truth/subjects.csv")) {
    truth[static_cast<int64_t>(Num(row, "frame"))] = row;
  }
  const Bank b(bank);
  std::vector<double> heading_error, scatter_along, across, off;
  int wrong_way = 0, sprites = 0;
  for (const ClipRecord& clip : b.ListClips()) {
    for (const SpriteRecord& s : b.LoadClipSprites(clip.id)) {
      ASSERT_EQ(s.kind, SpriteKind::kFloor) << "sprite " << s.id;
      EXPECT_EQ(s.billboard_width_px, s.billboard_height_px) << "a floor sprite is square";
      EXPECT_DOUBLE_EQ(s.anchor_x_px, (s.billboard_width_px - 1) / 2.0);
      if (s.mirrored) continue;
      const auto& t = truth.at(s.frame);
      const double h = Num(t, "heading_rad");
      const double e = std::abs(std::remainder(s.heading_rad - h, 2 * M_PI));
      heading_error.push_back(e);
      wrong_way += e > M_PI / 2 ? 1 : 0;
      const double dx = s.ground_x_m - Num(t, "x"), dy = s.ground_y_m - Num(t, "y");
      scatter_along.push_back(dx * std::cos(h) + dy * std::sin(h));
      across.push_back(-dx * std::sin(h) + dy * std::cos(h));
      off.push_back(std::hypot(dx, dy));
      ++sprites;
    }
  }
  ASSERT_EQ(sprites, j["sprites_kept"].get<int>());
  // Measured: seed 11, 20 s at 640x480: 1.5 degrees median, none tail first; the place (the
  // body's thickest part, issue 38: within 5 mm of the truth's root, median) 2.3 mm from the
  // root, 0.1 mm ahead, 0 mm aside; the outline's centre stood 9 mm ahead.
  EXPECT_LT(MedianOf(heading_error), 4 * M_PI / 180);
  EXPECT_LE(wrong_way, sprites / 50) << "sprites facing tail first";
  EXPECT_LE(MedianOf(off), 0.005);
  EXPECT_LT(std::abs(MedianOf(scatter_along)), 0.004);
  EXPECT_LT(std::abs(MedianOf(across)), 0.003);
}

}  // namespace
}  // namespace ss
