#include "pipeline/run/clip_batcher.h"

#include <gtest/gtest.h>

#include <set>

#include "core/error.h"

namespace ss {
namespace {

// A sprite of frame `f` walking along +x at 0.3 m/s, 30 fps, billboard facing -y.
MadeSprite Walking(int64_t f) {
  MadeSprite s;
  s.frame = f;
  s.timestamp_ns = f * 33'333'333;
  s.billboard.bgra = cv::Mat(20, 11, CV_8UC4, cv::Scalar(1, 2, 3, 255));
  s.billboard.shadow = cv::Mat::zeros(9, 9, CV_8U);
  s.billboard.anchor_px = Eigen::Vector2d(5, 19);
  s.billboard.point_in_ground = Eigen::Vector3d(0.3 * f / 30.0, 0.1, 0);
  s.billboard.right_in_ground = Eigen::Vector2d(1, 0);
  s.billboard.toward_camera = Eigen::Vector2d(0, -1);
  s.billboard.px_per_m = 800;
  s.description.area_px = 200;
  return s;
}

// A merged sprite (two subjects in one blob) is stored tagged `merged`, its mirror too, in the
// same batch as the sprite itself; the others carry no tag.
TEST(ClipBatcher, MergedSpritesCarryTheTagInTheirOwnBatch) {
  ClipBatcher batcher(7, {.min_clip_frames = 2, .batch_frames = 100});
  std::vector<ClipBatch> out;
  for (int f = 0; f < 6; ++f) {
    MadeSprite s = Walking(f);
    s.merged = f >= 2 && f < 4;
    batcher.Add(1, 3, std::move(s), &out);
  }
  batcher.Close(1, &out);
  ASSERT_EQ(out.size(), 1u);
  ASSERT_EQ(out[0].sprites.size(), 12u);
  for (const SpriteRecord& r : out[0].sprites) {
    const bool merged = r.frame >= 2 && r.frame < 4;
    EXPECT_EQ(r.tags, merged ? std::vector<std::string>{kMergedTag} : std::vector<std::string>{})
        << "frame " << r.frame << (r.mirrored ? " mirror" : "");
  }
  EXPECT_EQ(batcher.stored_originals(), 6u);
  EXPECT_EQ(batcher.stored_merged_originals(), 2u);
}

// A pair walked in together: frames 0-3 went out in a first batch, 4-6 are held back when frame 6
// shows the split. MarkMerged tags the wide ones still held; the narrow one (the pair one behind
// the other) and the sprites already handed out stay as they are.
TEST(ClipBatcher, MarkMergedTagsTheWideSpritesStillHeld) {
  ClipBatcher batcher(
      1, {.min_clip_frames = 2, .batch_frames = 4, .velocity_half_window = 1, .mirrors = false});
  std::vector<ClipBatch> out;
  const std::vector<double> widths = {1.0, 1.1, 1.0, 1.2, 0.5, 1.1, 1.0};  // one is 0.5 m
  for (int f = 0; f < 7; ++f) {
    MadeSprite s = Walking(f);
    s.matte_width_m = widths[f];
    batcher.Add(4, 2, std::move(s), &out);
  }
  EXPECT_FALSE(batcher.MarkedMerged(4));
  const size_t handed_out = out.empty() ? 0 : out[0].sprites.size();
  ASSERT_EQ(handed_out, 4u);  // frames 0-3 (batch_frames 4, one held for the velocity)
  batcher.MarkMerged(4, 0.75);
  batcher.MarkMerged(99, 0.75);  // no such clip: nothing
  EXPECT_TRUE(batcher.MarkedMerged(4));
  EXPECT_FALSE(batcher.MarkedMerged(99));
  batcher.Close(4, &out);
  std::vector<int64_t> tagged;
  for (const ClipBatch& b : out) {
    for (const SpriteRecord& r : b.sprites)
      if (!r.tags.empty()) tagged.push_back(r.frame);
  }
  EXPECT_EQ(tagged, (std::vector<int64_t>{5, 6}));
  EXPECT_EQ(batcher.stored_merged_originals(), 2u);
}

TEST(ClipBatcher, ShortClipsAreDroppedAndCounted) {
  ClipBatcher batcher(7, {.min_clip_frames = 5, .batch_frames = 3});
  std::vector<ClipBatch> out;
  for (int f = 0; f < 4; ++f) batcher.Add(1, 3, Walking(f), &out);
  batcher.Close(1, &out);
  EXPECT_TRUE(out.empty());
  EXPECT_EQ(batcher.short_clip_sprites(), 4u);
  EXPECT_EQ(batcher.stored_originals(), 0u);
  EXPECT_EQ(batcher.open_clips(), 0u);
}

TEST(ClipBatcher, LongClipGoesOutInBatchesEveryFrameOnceWithItsMirror) {
  ClipBatcher batcher(7, {.min_clip_frames = 5, .batch_frames = 4, .velocity_half_window = 2});
  std::vector<ClipBatch> out;
  for (int f = 100; f < 117; ++f) batcher.Add(9, 3, Walking(f), &out);
  EXPECT_FALSE(out.empty());  // batches leave while the clip is still open
  for (const ClipBatch& b : out) EXPECT_FALSE(b.clip.complete);
  batcher.Close(9, &out);
  ASSERT_TRUE(out.back().clip.complete);
  EXPECT_EQ(out.back().clip.last_frame, 116);

  std::set<int64_t> originals;
  int64_t expected_next = 100;
  for (const ClipBatch& b : out) {
    EXPECT_EQ(b.clip.camera_id, 7);
    EXPECT_EQ(b.clip.track_id, 3);
    EXPECT_EQ(b.clip.first_frame, 100);
    ASSERT_EQ(b.sprites.size() % 2, 0u);
    for (size_t k = 0; k < b.sprites.size(); k += 2) {
      const SpriteRecord& o = b.sprites[k];
      const SpriteRecord& m = b.sprites[k + 1];
      EXPECT_EQ(o.frame, expected_next++);
      EXPECT_TRUE(originals.insert(o.frame).second);
      EXPECT_FALSE(o.mirrored);
      EXPECT_FALSE(o.pixels.bgra.empty());
      EXPECT_TRUE(m.mirrored);
      EXPECT_EQ(m.frame, o.frame);
      EXPECT_TRUE(m.pixels.bgra.empty());
      // Walking right at 0.3 m/s; the mirror walks left, same toward/away component.
      EXPECT_NEAR(o.velocity_x_m_s, 0.3, 1e-6);
      EXPECT_NEAR(o.velocity_y_m_s, 0.0, 1e-6);
      EXPECT_NEAR(m.velocity_x_m_s, -0.3, 1e-6);
      EXPECT_NEAR(m.anchor_x_px, 10 - o.anchor_x_px, 1e-12);
      EXPECT_EQ(o.ground_x_m, m.ground_x_m);
    }
    EXPECT_EQ(b.clip.last_frame, expected_next - 1);
  }
  EXPECT_EQ(originals.size(), 17u);
  EXPECT_EQ(batcher.stored_originals(), 17u);
  EXPECT_EQ(batcher.clips_completed(), 1u);
}

TEST(ClipBatcher, RefusesAGapInsideAClip) {
  ClipBatcher batcher(1, {});
  std::vector<ClipBatch> out;
  batcher.Add(0, 0, Walking(0), &out);
  EXPECT_THROW(batcher.Add(0, 0, Walking(2), &out), WorkError);
}

}  // namespace
}  // namespace ss
