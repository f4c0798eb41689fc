// The extractor on keyed frames with known truth (key_scene.h): one candidate
// per subject with its box, alpha, colour, shadow and lowest point; noise
// blobs below the minimum area dropped and counted.
#include <algorithm>
#include <cmath>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "pipeline/extract/extractor.h"
#include "pipeline/key/chroma_keyer.h"
#include "tests/pipeline/key_scene.h"

namespace ss {
namespace {

using testing::KeyScene;
using testing::SceneFrame;
using testing::SceneOptions;
using testing::SceneSubject;

SceneSubject Hamster(cv::Point2d centre, double rx = 60, double ry = 40) {
  SceneSubject s;
  s.centre = centre;
  s.rx = rx;
  s.ry = ry;
  return s;
}

// A keyer trained on the scene's empty enclosure.
class ExtractorTest : public ::testing::Test {
 protected:
  ExtractorTest() : scene_(SceneOptions{}) {
    std::vector<cv::Mat> empty;
    empty.reserve(4);
    for (int i = 0; i < 4; ++i) empty.push_back(scene_.Empty(1000 + i));
    keyer_.Train(empty);
  }
  // Renders `subjects` and keys the frame into matte_.
  SceneFrame Key(const std::vector<SceneSubject>& subjects, int index = 1) {
    SceneFrame f = scene_.Render(subjects, index);
    keyer_.Key(f.bgr, matte_);
    return f;
  }

  KeyScene scene_;
  ChromaKeyer keyer_;
  Matte matte_;
};

// The true alpha of one subject alone (other subjects' pixels zeroed).
cv::Mat TruthOf(const KeyScene& scene, const SceneSubject& s, int index) {
  return scene.Render({s}, index).alpha;
}

// The candidate's alpha pasted into an empty full frame.
cv::Mat Pasted(const Candidate& c, cv::Size frame) {
  cv::Mat full = cv::Mat::zeros(frame, CV_8U);
  c.alpha.copyTo(full(c.bbox));
  return full;
}

// The candidate whose box holds `p`, or nullptr.
const Candidate* At(const std::vector<Candidate>& cands, cv::Point2d p) {
  for (const Candidate& c : cands) {
    if (c.bbox.contains(cv::Point(static_cast<int>(p.x), static_cast<int>(p.y)))) return &c;
  }
  return nullptr;
}

TEST_F(ExtractorTest, OneSubjectGivesItsBoxAlphaShadowAndLowestPoint) {
  const SceneSubject s = Hamster({310.4, 230.7});
  const SceneFrame f = Key({s});
  Extractor extractor;
  const std::vector<Candidate>& cands = extractor.Extract(matte_);
  ASSERT_EQ(cands.size(), 1u);
  const Candidate& c = cands[0];

  // Box: the true subject (alpha > 0) plus the margin, and the keyed shadow, all inside.
  const cv::Rect truth_box = cv::boundingRect(f.alpha > 0);
  const int m = extractor.options().margin_px;
  const cv::Rect with_margin(truth_box.x - m, truth_box.y - m, truth_box.width + 2 * m,
                             truth_box.height + 2 * m);
  EXPECT_EQ(c.bbox & with_margin, with_margin) << c.bbox << " should hold " << with_margin;
  const cv::Rect shadow_box = cv::boundingRect(matte_.shadow >= extractor.options().shadow_min);
  ASSERT_FALSE(shadow_box.empty());
  EXPECT_EQ(c.bbox & shadow_box, shadow_box) << c.bbox << " should hold the shadow " << shadow_box;

  // Layers are the matte's, cut to the box.
  ASSERT_EQ(c.alpha.size(), c.bbox.size());
  ASSERT_EQ(c.colour.size(), c.bbox.size());
  ASSERT_EQ(c.shadow.size(), c.bbox.size());
  EXPECT_EQ(cv::norm(c.alpha, matte_.alpha(c.bbox), cv::NORM_INF), 0);
  EXPECT_EQ(cv::norm(c.colour, matte_.colour(c.bbox), cv::NORM_INF), 0);
  EXPECT_EQ(cv::norm(c.shadow, matte_.shadow(c.bbox), cv::NORM_INF), 0);
  EXPECT_GE(testing::SoftIoU(f.alpha, Pasted(c, f.bgr.size())), 0.95);
  // The keyed shadow under the subject is the true darkening.
  const cv::Mat in_shadow = ((f.darkening > 0.15) & (f.alpha == 0))(c.bbox);
  ASSERT_GT(cv::countNonZero(in_shadow), 300);
  EXPECT_NEAR(cv::mean(c.shadow, in_shadow)[0] / 255, cv::mean(f.darkening(c.bbox), in_shadow)[0],
              0.05);
  // Colour inside the subject is the frame's.
  const cv::Mat inside = (f.alpha >= 1)(c.bbox) & (f.rim == 0)(c.bbox);
  cv::Mat diff;
  cv::absdiff(c.colour, f.bgr(c.bbox), diff);
  EXPECT_LT(cv::mean(diff, inside)[0] + cv::mean(diff, inside)[2], 0.5);

  // Area: the sum of true alpha; lowest point: where alpha falls through 1/2 at the bottom.
  EXPECT_NEAR(c.area, cv::sum(f.alpha)[0], 0.02 * cv::sum(f.alpha)[0]);
  const cv::Point2d low = KeyScene::LowestPoint(s);
  EXPECT_NEAR(c.contact_point.x, low.x, 1.0);
  EXPECT_NEAR(c.contact_point.y, low.y, 0.5);
  EXPECT_FALSE(c.touches_border);
  EXPECT_EQ(extractor.dropped_last(), 0);
}

TEST_F(ExtractorTest, SeveralSubjectsEachGetTheirOwnCandidate) {
  const std::vector<SceneSubject> subjects = {
      Hamster({130.2, 110.5}), Hamster({470.6, 140.3}, 45, 30), Hamster({300.3, 370.8}, 70, 45)};
  const SceneFrame f = Key(subjects);
  Extractor extractor;
  const std::vector<Candidate>& cands = extractor.Extract(matte_);
  ASSERT_EQ(cands.size(), 3u);
  for (const SceneSubject& s : subjects) {
    const Candidate* c = At(cands, s.centre);
    ASSERT_NE(c, nullptr) << "no candidate at " << s.centre;
    const cv::Mat truth = TruthOf(scene_, s, 1);
    EXPECT_GE(testing::SoftIoU(truth, Pasted(*c, f.bgr.size())), 0.95) << "subject at " << s.centre;
    EXPECT_NEAR(c->contact_point.y, KeyScene::LowestPoint(s).y, 0.5) << "subject at " << s.centre;
    // Spill greens the rim: the keyed edge sits about half a pixel inside the true one.
    const double perimeter = 2 * CV_PI * std::sqrt((s.rx * s.rx + s.ry * s.ry) / 2);
    EXPECT_NEAR(c->area, cv::sum(truth)[0], 0.6 * perimeter) << "subject at " << s.centre;
  }
}

// Two subjects whose boxes overlap while their cells do not touch: each
// candidate holds its own subject only.
TEST_F(ExtractorTest, OverlappingBoxesDoNotShareSubjects) {
  const std::vector<SceneSubject> subjects = {Hamster({200.3, 180.2}), Hamster({345.7, 262.4})};
  const SceneFrame f = Key(subjects);
  ASSERT_EQ(matte_.regions.size(), 2u) << "the subjects' cells touch: move them apart";
  ASSERT_TRUE(matte_.regions[0].overlaps_other)
      << "the boxes do not overlap: move the subjects closer";
  Extractor extractor;
  const std::vector<Candidate>& cands = extractor.Extract(matte_);
  ASSERT_EQ(cands.size(), 2u);
  for (size_t i = 0; i < subjects.size(); ++i) {
    const Candidate* c = At(cands, subjects[i].centre);
    ASSERT_NE(c, nullptr);
    const cv::Mat own = TruthOf(scene_, subjects[i], 1),
                  other = TruthOf(scene_, subjects[1 - i], 1);
    const cv::Mat pasted = Pasted(*c, f.bgr.size());
    EXPECT_GE(testing::SoftIoU(own, pasted), 0.95) << "subject " << i;
    EXPECT_EQ(cv::countNonZero(pasted & (other > 0)), 0)
        << "subject " << i << " holds the other's pixels";
    EXPECT_NEAR(c->area, cv::sum(own)[0], 0.02 * cv::sum(own)[0]) << "subject " << i;
  }
}

// A blob below the minimum area is noise: dropped and counted; with a smaller
// minimum it is a candidate like any other.
TEST_F(ExtractorTest, BlobsBelowTheMinimumAreaAreDropped) {
  SceneSubject speck = Hamster({500.5, 380.5}, 7, 7);
  speck.shadow_depth = 0;
  speck.spill = 0;
  const SceneFrame f = Key({Hamster({220.5, 200.5}), speck});
  ASSERT_EQ(matte_.regions.size(), 2u) << "the keyer should find the speck";
  const double speck_area = cv::sum(TruthOf(scene_, speck, 1))[0];
  ASSERT_LT(speck_area, 200);

  ExtractorOptions strict;
  strict.min_area = 200;
  Extractor extractor(strict);
  ASSERT_EQ(extractor.Extract(matte_).size(), 1u);
  EXPECT_EQ(extractor.dropped_last(), 1);
  EXPECT_NE(At(extractor.Extract(matte_), {220.5, 200.5}), nullptr);
  EXPECT_EQ(extractor.totals().frames, 2u);
  EXPECT_EQ(extractor.totals().candidates, 2u);
  EXPECT_EQ(extractor.totals().noise_dropped, 2u);

  ExtractorOptions loose;
  loose.min_area = 40;
  Extractor keeps(loose);
  const std::vector<Candidate>& cands = keeps.Extract(matte_);
  ASSERT_EQ(cands.size(), 2u);
  const Candidate* c = At(cands, speck.centre);
  ASSERT_NE(c, nullptr);
  EXPECT_NEAR(c->area, speck_area, 0.1 * speck_area);
  EXPECT_EQ(keeps.dropped_last(), 0);
}

TEST_F(ExtractorTest, SubjectAtTheImageEdgeIsMarked) {
  Key({Hamster({30.5, 240.5}), Hamster({400.5, 240.5})});
  Extractor extractor;
  const std::vector<Candidate>& cands = extractor.Extract(matte_);
  ASSERT_EQ(cands.size(), 2u);
  ASSERT_NE(At(cands, {30.5, 240.5}), nullptr);
  ASSERT_NE(At(cands, {400.5, 240.5}), nullptr);
  EXPECT_TRUE(At(cands, {30.5, 240.5})->touches_border);
  EXPECT_EQ(At(cands, {30.5, 240.5})->bbox.x, 0);
  EXPECT_FALSE(At(cands, {400.5, 240.5})->touches_border);
}

TEST_F(ExtractorTest, EmptyFramesAndReuse) {
  Extractor extractor;
  Key({});
  EXPECT_TRUE(extractor.Extract(matte_).empty());
  // Buffers are reused: a big subject, then a small one elsewhere, then two.
  Key({Hamster({320.5, 240.5}, 120, 80)}, 2);
  ASSERT_EQ(extractor.Extract(matte_).size(), 1u);
  const SceneSubject small = Hamster({100.5, 100.5}, 30, 20);
  const SceneFrame f = Key({small}, 3);
  const std::vector<Candidate>& cands = extractor.Extract(matte_);
  ASSERT_EQ(cands.size(), 1u);
  EXPECT_GE(testing::SoftIoU(f.alpha, Pasted(cands[0], f.bgr.size())), 0.95);
  EXPECT_EQ(extractor.totals().frames, 3u);
  EXPECT_EQ(extractor.totals().candidates, 2u);
}

TEST(Extractor, RefusesBadOptions) {
  ExtractorOptions o;
  o.min_area = -1;
  EXPECT_THROW(Extractor{o}, InputError);
  o = {};
  o.alpha_min = 0;
  EXPECT_THROW(Extractor{o}, InputError);
  o = {};
  o.margin_px = -2;
  EXPECT_THROW(Extractor{o}, InputError);
}

}  // namespace
}  // namespace ss
