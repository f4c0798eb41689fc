// The synthetic sprites and banks of transitions_bank_fixtures.h.
#include "tests/pipeline/transitions_bank_fixtures.h"

#include <algorithm>
#include <filesystem>
#include <fstream>

#include <opencv2/core.hpp>

namespace ss::testing {
namespace {

constexpr int64_t kFrameNs = 33'333'333;

}  // namespace

SpriteRecord Record(const SyntheticSprite& s, int64_t frame, bool mirrored) {
  const double px_per_m = SyntheticSpriteOptions{}.px_per_m;
  SpriteRecord r;
  r.frame = frame;
  r.timestamp_ns = frame * kFrameNs;
  r.mirrored = mirrored;
  r.ground_x_m = 0.001 * frame;
  r.ground_y_m = 0.5;
  r.velocity_x_m_s = s.cheap.velocity_x_mps;
  r.velocity_y_m_s = s.cheap.velocity_y_mps;
  r.mean_r = s.cheap.colour[0];
  r.mean_g = s.cheap.colour[1];
  r.mean_b = s.cheap.colour[2];
  r.area_px = s.cheap.area_m2 * px_per_m * px_per_m;
  r.eccentricity = s.cheap.eccentricity;
  r.billboard_width_px = s.billboard.width;
  r.billboard_height_px = s.billboard.height;
  r.px_per_m = px_per_m;
  r.anchor_x_px = s.billboard.anchor_x_px;
  r.anchor_y_px = s.billboard.anchor_y_px;
  r.bbox_in_image = cv::Rect(0, 0, s.billboard.width, s.billboard.height);
  if (!mirrored) {
    r.pixels.bgra = cv::Mat(s.billboard.height, s.billboard.width, CV_8UC4,
                            const_cast<uint8_t*>(s.billboard.rgba.data()))
                        .clone();
  }
  return r;
}

std::vector<SyntheticSprite> Sprites(int frames, uint64_t seed) {
  SyntheticSpriteOptions o;
  o.frames = frames;
  o.min_clip_frames = 10;
  o.max_clip_frames = 60;
  o.seed = seed;
  auto sprites = MakeSyntheticSprites(o);
  for (auto& s : sprites) {
    const double area_px = s.cheap.area_m2 * o.px_per_m * o.px_per_m;
    s.cheap.area_m2 = area_px / (o.px_per_m * o.px_per_m);
  }
  return sprites;
}

std::vector<ClipOfSprites> Clips(const std::vector<SyntheticSprite>& sprites) {
  const size_t half = sprites.size() / 2;
  std::map<int64_t, ClipOfSprites> by_clip;
  for (size_t k = 0; k < half; ++k) {
    auto& c = by_clip[sprites[k].clip];
    c.clip = sprites[k].clip;
    c.originals.push_back(&sprites[k]);
    c.mirrors.push_back(&sprites[half + k]);
  }
  std::vector<ClipOfSprites> out;
  out.reserve(by_clip.size());
  for (auto& [id, c] : by_clip) out.push_back(c);
  return out;
}

BankFiller::BankFiller(const std::string& path) : writer_(path) {
  const int64_t session = writer_.AddSession({0, "synthetic@test", "synthetic", "", "test"});
  camera_ = writer_.AddCamera(session, {0, 0, "cam0", "", 640, 480});
}

void BankFiller::Add(const ClipOfSprites& c, int batch,
                     const std::function<void(const std::vector<int64_t>&)>& stored) {
  ClipRecord clip;
  clip.camera_id = camera_;
  clip.track_id = c.clip;
  clip.first_frame = next_frame_;
  for (size_t begin = 0; begin < c.originals.size(); begin += batch) {
    const size_t end = std::min(c.originals.size(), begin + batch);
    std::vector<SpriteRecord> records;
    std::vector<int64_t> synthetic_ids;
    for (size_t k = begin; k < end; ++k) {
      records.push_back(Record(*c.originals[k], next_frame_ + static_cast<int64_t>(k), false));
      synthetic_ids.push_back(c.originals[k]->id);
      records.push_back(Record(*c.mirrors[k], next_frame_ + static_cast<int64_t>(k), true));
      synthetic_ids.push_back(c.mirrors[k]->id);
      if (merged.count(c.originals[k]->id)) {  // tagged in the sprite's own batch
        records[records.size() - 2].tags = {kMergedTag};
        records.back().tags = {kMergedTag};
      }
    }
    clip.complete = end == c.originals.size();
    clip.last_frame = next_frame_ + static_cast<int64_t>(end) - 1;
    const AppendResult r = writer_.AppendClipBatch(clip, records);
    for (size_t k = 0; k < r.sprite_ids.size(); ++k) bank_id[synthetic_ids[k]] = r.sprite_ids[k];
    if (stored) stored(r.sprite_ids);
  }
  next_frame_ += static_cast<int64_t>(c.originals.size()) + 10;  // a gap between clips
}

void WriteTruth(const std::string& session_dir, const std::vector<SyntheticSprite>& sprites) {
  std::filesystem::create_directories(std::filesystem::path(session_dir) / "truth");
  std::ofstream out(std::filesystem::path(session_dir) / "truth" / "subjects.csv");
  out.precision(17);
  out << "frame,timestamp_ns,subject,kind,x,y,heading_rad,speed_mps,gait_phase,pose,touches_wall,"
         "leaves_floor,"
         "height_m\n";
  int64_t frame = 100;
  for (const auto& c : Clips(sprites)) {
    for (const SyntheticSprite* s : c.originals) {
      out << frame << ',' << frame * kFrameNs << ",0,animal," << 0.001 * frame << ",0.5,"
          << s->truth.heading_rad << ',' << s->speed_mps << ',' << s->truth.gait_phase << ','
          << s->truth.pose << ",0,0,0.1\n";
      // A second subject far away must not be matched.
      out << frame << ',' << frame * kFrameNs << ",1,animal,5,5,0,0,0.5,stand,0,0,0.1\n";
      ++frame;
    }
    frame += 10;
  }
}

}  // namespace ss::testing
