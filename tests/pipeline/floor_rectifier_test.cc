// Floor sprites (pipeline/rectify/floor_rectifier.h) against the synthetic studio's truth: an
// animal walking in the enclosure seen by a camera overhead (synth's `--view overhead`), keyed
// by the chroma keyer trained on the empty enclosure, its candidates laid on the floor. Their
// centres and headings are compared with where the animal is and which way it faces.
#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "core/camera_model.h"
#include "core/frame.h"
#include "pipeline/extract/extractor.h"
#include "pipeline/key/chroma_keyer.h"
#include "pipeline/rectify/floor_rectifier.h"
#include "synth/directors.h"
#include "synth/renderer.h"
#include "synth/scene.h"
#include "tests/pipeline/synth_clean_plate.h"

namespace ss {
namespace {

constexpr int kOverheadWidth = 640;
constexpr int kOverheadHeight = 480;
constexpr double kFps = 30;

double Median(std::vector<double> v) {
  if (v.empty()) return std::nan("");
  std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

double AngleBetween(double a, double b) { return std::abs(std::remainder(a - b, 2 * M_PI)); }

struct FloorRun {
  // The centre's offset from the truth's root, along the truth's heading and to its left.
  std::vector<double> along_m, across_m;
  std::vector<double> heading_error_rad;  // the resolved heading against the truth's
  // The body's thickest part (the centre moved by thickest_ahead_m): its distance to the root.
  std::vector<double> thickest_off_m;
  int frames_seen = 0;
};

// `frames` consecutive frames (from `first`) of one animal under one overhead camera.
FloorRun RunOverhead(uint64_t seed, int first, int frames) {
  using namespace synth;
  const Studio studio = MakeStudio(StudioKind::kEnclosure, seed);
  const std::vector<SynthCamera> cameras =
      MakeCameras(studio, 1, kOverheadWidth, kOverheadHeight, seed, CameraView::kOverhead);
  const CameraRenderer renderer(cameras[0], studio);
  const Sensor sensor(seed, 0, 1.0);
  const SynthCamera& cam = cameras[0];
  const CameraModel model(cam.lensmodel, cam.intrinsics, cam.width, cam.height,
                          cam.cam_from_ground);

  ChromaKeyer keyer;
  keyer.Train(testing::CleanPlateFrames(renderer, sensor, PixelFormat::kRGB8));
  ExtractorOptions extract;
  extract.min_area = 400;
  Extractor extractor(extract);
  const FloorRectifier rectifier;

  DirectorOptions options;
  options.subjects = 1;
  options.seed = seed;
  std::unique_ptr<Director> director = MakeAnimalDirector(studio, cameras, options);
  FrameSnapshot snap;
  CameraImage image;
  Matte matte;
  cv::Mat scratch;
  std::vector<Billboard> sprites;
  std::vector<SubjectTruth> truths;
  for (int i = 0; i < first + frames; ++i) {
    director->Frame(i / kFps, &snap);
    if (i < first) continue;
    renderer.Render(snap.scene, &image);
    const Frame f = Frame::Owned(PixelFormat::kRGB8, kOverheadWidth, kOverheadHeight,
                                 sensor.Capture(image.bgr, PixelFormat::kRGB8, i));
    keyer.Key(f, scratch, matte);
    const std::vector<Candidate>& found = extractor.Extract(matte);
    if (found.size() != 1 || found[0].touches_border) continue;
    const Candidate& c = found[0];
    const SpriteView view{&c.colour, &c.alpha, &c.shadow, c.bbox.tl(),
                          Eigen::Vector2d(c.contact_point.x, c.contact_point.y)};
    const auto sprite = rectifier.Rectify(model, view);
    if (!sprite) continue;
    sprites.push_back(*sprite);
    truths.push_back(snap.subjects[0]);
  }
  // One clip: velocities from the centres (central differences), then the signs.
  std::vector<HeadingCue> cues(sprites.size());
  for (size_t t = 0; t < sprites.size(); ++t) {
    const size_t a = t == 0 ? 0 : t - 1, b = std::min(t + 1, sprites.size() - 1);
    cues[t].axis_rad = sprites[t].heading_rad;
    cues[t].elongation = sprites[t].elongation;
    if (b > a) {
      cues[t].velocity = (sprites[b].point_in_ground - sprites[a].point_in_ground).head<2>() *
                         kFps / static_cast<double>(b - a);
    }
  }
  const std::vector<bool> flip = ResolveHeadings(cues);
  FloorRun run;
  run.frames_seen = static_cast<int>(sprites.size());
  for (size_t t = 0; t < sprites.size(); ++t) {
    const Billboard s = flip[t] ? FloorRectifier::TurnHalf(sprites[t]) : sprites[t];
    const Eigen::Vector2d d = s.point_in_ground.head<2>() - truths[t].position;
    const Eigen::Vector2d f(std::cos(truths[t].heading_rad), std::sin(truths[t].heading_rad));
    run.along_m.push_back(d.dot(f));
    run.across_m.push_back(f.x() * d.y() - f.y() * d.x());
    run.heading_error_rad.push_back(AngleBetween(s.heading_rad, truths[t].heading_rad));
    run.thickest_off_m.push_back((d + s.thickest_ahead_m * f).norm());
  }
  return run;
}

// The sprite's centre is the centre of the animal's outline seen from above: a point of its
// body ahead of the truth's root (the floor point under the body's centre) by about the head's
// share, and steady there (floor_height_m 0.03: 1.1-1.4 mm of scatter; on the floor itself,
// 2.7-5.4 mm). Its heading is the truth's, head first. The body's thickest part, where the clip
// batcher moves the place, lies within 5 mm of the root (issue 38's goal; 0.5-0.7 mm behind it).
TEST(FloorRectifier, AnAnimalSeenFromAboveLiesWhereItIsAndFacesItsWay) {
  for (const uint64_t seed : {3, 8}) {
    const FloorRun run = RunOverhead(seed, 45, 90);
    SCOPED_TRACE(seed);
    ASSERT_GE(run.frames_seen, 80) << "the animal should be keyed in nearly every frame";
    const double ahead = Median(run.along_m), aside = Median(run.across_m);
    std::vector<double> scatter, wrong_way;
    for (size_t i = 0; i < run.along_m.size(); ++i) {
      scatter.push_back(std::hypot(run.along_m[i] - ahead, run.across_m[i]));
      if (run.heading_error_rad[i] > M_PI / 2) wrong_way.push_back(i);
    }
    const std::string tag = "seed" + std::to_string(seed) + "_";
    RecordProperty(tag + "ahead_mm", std::to_string(ahead * 1000));
    RecordProperty(tag + "scatter_mm", std::to_string(Median(scatter) * 1000));
    RecordProperty(tag + "heading_deg", std::to_string(Median(run.heading_error_rad) * 180 / M_PI));
    EXPECT_GT(ahead, 0.0);
    EXPECT_LT(ahead, 0.015);
    EXPECT_LE(Median(run.thickest_off_m), 0.005);
    RecordProperty(tag + "thickest_mm", std::to_string(Median(run.thickest_off_m) * 1000));
    EXPECT_LT(std::abs(aside), 0.002);
    EXPECT_LE(Median(scatter), 0.003);
    EXPECT_LE(Median(run.heading_error_rad), 3.5 * M_PI / 180);
    EXPECT_LE(wrong_way.size(), run.along_m.size() / 20) << "frames facing tail first";
  }
}

// Clip signs: an axis whose sign the moments leave open, flipped at random, is turned head
// first where the subject walks, and kept turning smoothly where it stands and turns.
TEST(FloorRectifier, HeadingsFollowTheWalkAndTurnSmoothlyWhereTheSubjectStands) {
  std::vector<HeadingCue> clip;
  std::vector<double> truth;
  uint32_t state = 12345;
  const auto coin = [&state] {
    state = state * 1664525u + 1013904223u;
    return (state >> 16) & 1u;
  };
  for (int t = 0; t < 120; ++t) {
    // Walks east for 40 frames, stands turning a quarter turn left over 40, walks north.
    const double heading = t < 40 ? 0.0 : t < 80 ? (t - 40) / 40.0 * M_PI / 2 : M_PI / 2;
    const double speed = t < 40 || t >= 80 ? 0.15 : 0.0;
    HeadingCue cue;
    cue.axis_rad = heading + (coin() != 0 ? M_PI : 0.0);
    cue.elongation = 0.4;
    cue.velocity = speed * Eigen::Vector2d(std::cos(heading), std::sin(heading));
    clip.push_back(cue);
    truth.push_back(heading);
  }
  const std::vector<bool> flip = ResolveHeadings(clip);
  ASSERT_EQ(flip.size(), clip.size());
  for (size_t t = 0; t < clip.size(); ++t) {
    const double resolved = clip[t].axis_rad + (flip[t] ? M_PI : 0.0);
    EXPECT_LT(AngleBetween(resolved, truth[t]), 1e-9) << "frame " << t;
  }
  EXPECT_TRUE(ResolveHeadings({}).empty());
}

// The keyer leaves no shadow where the body hides the floor from the camera. Laid on the floor,
// that hole must lie under the body, wherever in the view the body was: off the middle of an
// overhead view, the body plane (3 cm up) and the floor are apart by the camera's parallax.
TEST(FloorRectifier, TheShadowsHoleLiesUnderTheBodyAnywhereInTheView) {
  using namespace synth;
  const Studio studio = MakeStudio(StudioKind::kEnclosure, 5);
  const SynthCamera cam =
      MakeCameras(studio, 1, kOverheadWidth, kOverheadHeight, 5, CameraView::kOverhead)[0];
  const CameraModel model(cam.lensmodel, cam.intrinsics, cam.width, cam.height,
                          cam.cam_from_ground);
  const FloorRectifier rectifier;
  // Centroid, relative to `centre`, of the pixels of `m` within `radius` of it that `take`s.
  const auto centroid = [](const cv::Mat& m, Eigen::Vector2d centre, double radius, auto take) {
    Eigen::Vector2d sum(0, 0);
    double n = 0;
    for (int y = 0; y < m.rows; ++y) {
      for (int x = 0; x < m.cols; ++x) {
        const Eigen::Vector2d d(x - centre.x(), y - centre.y());
        if (d.norm() <= radius && take(m, x, y)) {
          sum += d;
          n += 1;
        }
      }
    }
    return Eigen::Vector2d(sum / std::max(1.0, n));
  };
  double worst_px = 0;
  for (const cv::Point at : {cv::Point(320, 240), cv::Point(110, 90), cv::Point(540, 400)}) {
    // A dark body (an ellipse 60 x 28 px) in a 200 x 200 px crop, shadow all round it but under it.
    const cv::Point offset(at.x - 100, at.y - 100);
    cv::Mat bgr(200, 200, CV_8UC3, cv::Scalar(30, 30, 30)), alpha(200, 200, CV_8U, cv::Scalar(0));
    cv::ellipse(alpha, cv::Point(100, 100), cv::Size(30, 14), 30, 0, 360, cv::Scalar(255),
                cv::FILLED);
    cv::Mat shadow(200, 200, CV_8U, cv::Scalar(255));
    shadow.setTo(0, alpha > 0);
    const SpriteView view{&bgr, &alpha, &shadow, offset, Eigen::Vector2d(at.x, at.y)};
    const auto sprite = rectifier.Rectify(model, view);
    ASSERT_TRUE(sprite) << "body at " << at;
    // Both drawn on the floor at the sprite's place: the image by its anchor, the shadow by its
    // centre, in the same axes and scale.
    const Eigen::Vector2d body =
        centroid(sprite->bgra, sprite->anchor_px, 0.5 * sprite->bgra.cols,
                 [](const cv::Mat& m, int x, int y) { return m.at<cv::Vec4b>(y, x)[3] > 127; });
    const double c = (sprite->shadow.cols - 1) / 2.0;
    // (within the crop's reach: outside it the patch is empty as well)
    const Eigen::Vector2d hole =
        centroid(sprite->shadow, Eigen::Vector2d(c, c), 0.06 * sprite->px_per_m,
                 [](const cv::Mat& m, int x, int y) { return m.at<uint8_t>(y, x) < 128; });
    worst_px = std::max(worst_px, (body - hole).norm());
    EXPECT_LT((body - hole).norm(), 0.25) << "body at " << at << ": the image's body centre "
                                          << body.transpose() << " px from the place, the shadow's "
                                          << "hole " << hole.transpose();
  }
  // Measured: 0.09 px; taken on the floor, as before, 0.78 px at the corner.
  RecordProperty("worst_offset_px", std::to_string(worst_px));
}

// Turning half a turn twice gives the sprite back; the mirror swaps the sides, not the ends.
TEST(FloorRectifier, TurnHalfAndMirrorKeepThePlaceAndTheCentre) {
  Billboard s;
  s.kind = SpriteKind::kFloor;
  s.bgra = cv::Mat(5, 5, CV_8UC4, cv::Scalar(0, 0, 0, 0));
  s.bgra.at<cv::Vec4b>(0, 2) = {255, 255, 255, 255};  // the nose, on the axis, ahead
  s.bgra.at<cv::Vec4b>(2, 0) = {0, 0, 255, 255};      // the left side
  s.shadow = cv::Mat::zeros(3, 3, CV_8U);
  s.anchor_px = {2, 2};
  s.point_in_ground = {0.1, 0.2, 0};
  s.heading_rad = 0.5;
  s.toward_camera = {std::cos(0.5), std::sin(0.5)};
  s.right_in_ground = {std::sin(0.5), -std::cos(0.5)};
  const Billboard turned = FloorRectifier::TurnHalf(s);
  EXPECT_NEAR(AngleBetween(turned.heading_rad, 0.5 + M_PI), 0, 1e-12);
  EXPECT_NEAR((turned.toward_camera + s.toward_camera).norm(), 0, 1e-12);
  EXPECT_EQ(turned.bgra.at<cv::Vec4b>(4, 2)[3], 255);  // the nose behind now
  EXPECT_EQ(turned.point_in_ground, s.point_in_ground);
  EXPECT_EQ(turned.anchor_px, s.anchor_px);
  const Billboard back = FloorRectifier::TurnHalf(turned);
  EXPECT_EQ(cv::norm(back.bgra, s.bgra, cv::NORM_INF), 0);
  EXPECT_NEAR(AngleBetween(back.heading_rad, 0.5), 0, 1e-12);
  const Billboard mirrored = Rectifier::Mirror(s);
  EXPECT_EQ(mirrored.bgra.at<cv::Vec4b>(0, 2)[3], 255);  // the nose stays ahead
  EXPECT_EQ(mirrored.bgra.at<cv::Vec4b>(2, 4)[2], 255);  // the left side is the right
  EXPECT_EQ(mirrored.heading_rad, s.heading_rad);
  EXPECT_EQ(mirrored.anchor_px, s.anchor_px);
  EXPECT_EQ(s.bgra.at<cv::Vec4b>(2, 0)[2], 255) << "the original keeps its pixels";
}

}  // namespace
}  // namespace ss
