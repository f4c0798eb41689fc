// The keyers against generated frames with known alpha and shadow (key_scene.h).
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "pipeline/key/chroma_keyer.h"
#include "pipeline/key/clean_plate_keyer.h"
#include "tests/pipeline/key_scene.h"

namespace ss {
namespace {

using testing::BinaryIoU;
using testing::KeyScene;
using testing::SceneBar;
using testing::SceneFrame;
using testing::SceneOptions;
using testing::SceneSubject;
using testing::SoftIoU;

std::vector<cv::Mat> EmptyFrames(const KeyScene& scene, int n) {
  std::vector<cv::Mat> frames;
  frames.reserve(n);
  for (int i = 0; i < n; ++i) frames.push_back(scene.Empty(1000 + i));
  return frames;
}

SceneSubject HamsterAt(cv::Point2d centre) {
  SceneSubject s;
  s.centre = centre;
  return s;
}

// Mean of `values` (CV_8U, scaled to 0..1) over the non-zero pixels of `mask`.
double MeanOver(const cv::Mat& values, const cv::Mat& mask) {
  if (cv::countNonZero(mask) == 0) return 0;
  return cv::mean(values, mask)[0] / 255.0;
}

// Alpha above 1/10 farther than `px` from the true subject.
int StrayAlpha(const SceneFrame& f, const cv::Mat& alpha, int px) {
  cv::Mat near = f.alpha > 0;
  cv::dilate(near, near,
             cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * px + 1, 2 * px + 1)));
  return cv::countNonZero((alpha > 25) & ~near);
}

struct Quality {
  double soft_iou, binary_iou;
  int stray;
};

Quality KeyQuality(const Keyer& keyer, const SceneFrame& f) {
  Matte m;
  keyer.Key(f.bgr, m);
  return {SoftIoU(f.alpha, m.alpha), BinaryIoU(f.alpha, m.alpha), StrayAlpha(f, m.alpha, 3)};
}

TEST(ChromaKeyer, SoftAlphaMatchesTruthOnUnevenGreen) {
  KeyScene scene(SceneOptions{});
  ChromaKeyer keyer;
  keyer.Train(EmptyFrames(scene, 6));
  for (const cv::Point2d c :
       {cv::Point2d(320.3, 240.6), cv::Point2d(90.5, 80.2), cv::Point2d(560.7, 420.4)}) {
    const Quality q = KeyQuality(keyer, scene.Render({HamsterAt(c)}, 1));
    EXPECT_GE(q.soft_iou, 0.95) << "subject at " << c;
    EXPECT_GE(q.binary_iou, 0.97) << "subject at " << c;
    EXPECT_EQ(q.stray, 0) << "subject at " << c;
  }
}

TEST(ChromaKeyer, EmptyFrameHasNoRegions) {
  KeyScene scene(SceneOptions{});
  ChromaKeyer keyer;
  keyer.Train(EmptyFrames(scene, 6));
  Matte m;
  for (int i = 0; i < 5; ++i) {
    keyer.Key(scene.Empty(i), m);
    EXPECT_TRUE(m.regions.empty()) << "frame " << i;
    EXPECT_EQ(cv::countNonZero(m.alpha), 0);
  }
}

// The generator is honest: a keyer with one global green reference (what a
// keyer tuned for flat green amounts to) passes on flat green and fails on the
// uneven floor, where the trained per-cell model passes.
TEST(ChromaKeyer, GlobalReferenceFailsOnUnevenGreen) {
  ChromaKeyerOptions global_options;
  global_options.global_model = true;
  const SceneSubject subject = HamsterAt({300.4, 260.7});

  SceneOptions flat;
  flat.tint = 0;
  flat.vignetting = 0;
  flat.unevenness = 0;
  KeyScene flat_scene(flat);
  ChromaKeyer flat_global(global_options);
  flat_global.Train(EmptyFrames(flat_scene, 6));
  const Quality on_flat = KeyQuality(flat_global, flat_scene.Render({subject}, 1));
  EXPECT_GE(on_flat.soft_iou, 0.95);
  EXPECT_EQ(on_flat.stray, 0);

  KeyScene uneven(SceneOptions{});
  ChromaKeyer trained;
  trained.Train(EmptyFrames(uneven, 6));
  ChromaKeyer global(global_options);
  global.Train(EmptyFrames(uneven, 6));
  const SceneFrame f = uneven.Render({subject}, 1);
  const Quality good = KeyQuality(trained, f);
  const Quality bad = KeyQuality(global, f);
  EXPECT_GE(good.soft_iou, 0.95);
  EXPECT_EQ(good.stray, 0);
  // The global keyer keys patches of yellower green as subject.
  EXPECT_GT(bad.stray, 1000);
  EXPECT_LT(bad.soft_iou, 0.9);

  // Its shadow layer also mistakes vignetting for shadow: on an empty frame
  // the trained keyer finds nothing, the global one finds dark corners.
  Matte m;
  trained.Key(uneven.Empty(3), m);
  EXPECT_TRUE(m.regions.empty());
  global.Key(uneven.Empty(3), m);
  EXPECT_FALSE(m.regions.empty());
}

TEST(ChromaKeyer, ShadowUnderTheSubjectAndNowhereElse) {
  KeyScene scene(SceneOptions{});
  ChromaKeyer keyer;
  keyer.Train(EmptyFrames(scene, 6));
  const SceneFrame f = scene.Render({HamsterAt({330.2, 250.5})}, 2);
  Matte m;
  keyer.Key(f.bgr, m);

  const cv::Mat off_subject = f.alpha == 0;
  const cv::Mat in_shadow = (f.darkening > 0.15) & off_subject;
  const cv::Mat no_shadow = (f.darkening < 0.01) & off_subject;
  ASSERT_GT(cv::countNonZero(in_shadow), 500);
  const double true_mean = cv::mean(f.darkening, in_shadow)[0];
  const double found_mean = MeanOver(m.shadow, in_shadow);
  EXPECT_NEAR(found_mean, true_mean, 0.05);
  EXPECT_LT(MeanOver(m.shadow, no_shadow), 0.005);
  EXPECT_EQ(cv::countNonZero((m.shadow > 25) & no_shadow), 0);
  // No shadow on the subject itself.
  EXPECT_LT(MeanOver(m.shadow, f.alpha >= 1), 0.005);
  // ...and the shadow is not keyed as subject.
  EXPECT_LT(MeanOver(m.alpha, in_shadow), 0.02);
}

// Spill on a brown subject does not make its rim greener than red (G stays
// below max(R, B)), it makes it olive: despill is measured against the
// subject's own colour, which the generator knows.
TEST(ChromaKeyer, DespillRemovesGreenFromTheRim) {
  KeyScene scene(SceneOptions{});
  ChromaKeyer keyer;
  keyer.Train(EmptyFrames(scene, 6));
  const SceneFrame f = scene.Render({HamsterAt({320, 240})}, 1);
  Matte m;
  keyer.Key(f.bgr, m);
  ASSERT_GT(cv::countNonZero(f.rim), 200);
  auto green_over_own = [&](const cv::Mat& bgr, const cv::Mat& mask) {  // mean G - true unspilled G
    cv::Mat g, own;
    cv::extractChannel(bgr, g, 1);
    g.convertTo(g, CV_32F);
    cv::extractChannel(f.clean, own, 1);
    return cv::mean(g - own, mask)[0];
  };
  const double spill_in = green_over_own(f.bgr, f.rim);
  const double spill_out = green_over_own(m.colour, f.rim);
  EXPECT_GT(spill_in, 15.0);  // the generator put spill there
  EXPECT_LT(spill_out, 0.5 * spill_in);
  EXPECT_GT(spill_out, -3.0);  // ...and took no more than the spill
  // Inside, away from the rim, colour is the frame's own (brown's G is below mean(R, B)).
  cv::Mat inner = (f.alpha >= 1) & (f.rim == 0);
  cv::Mat diff;
  cv::absdiff(f.bgr, m.colour, diff);
  EXPECT_LT(cv::mean(diff, inner)[1], 0.5);

  // Bias 0 (G <= max(R, B)) keeps yellows but leaves a brown rim's spill alone.
  ChromaKeyerOptions keep_yellow;
  keep_yellow.despill.bias = 0;
  ChromaKeyer conservative(keep_yellow);
  conservative.Train(EmptyFrames(scene, 6));
  conservative.Key(f.bgr, m);
  EXPECT_GT(green_over_own(m.colour, f.rim), 0.9 * spill_in);
}

// A subject as thin as step + 2 px is always found, whatever its phase
// against the coarse grid, upright or diagonal.
TEST(ChromaKeyer, ThinPartsAreNotLost) {
  KeyScene scene(SceneOptions{});
  ChromaKeyer keyer;
  keyer.Train(EmptyFrames(scene, 4));
  Matte m;
  for (int phase = 0; phase < 8; ++phase) {
    for (double angle : {90.0, 0.0, 45.0, 30.0}) {
      SceneSubject s;
      s.rx = 0;
      s.shadow_depth = 0;
      s.bars.push_back(SceneBar{{200.0 + phase, 200.0 + phase * 0.5}, 120, 10, angle});
      const SceneFrame f = scene.Render({s}, phase);
      keyer.Key(f.bgr, m);
      EXPECT_EQ(m.regions.size(), 1u) << "phase " << phase << " angle " << angle;
      EXPECT_GE(SoftIoU(f.alpha, m.alpha), 0.9) << "phase " << phase << " angle " << angle;
    }
  }
}

TEST(ChromaKeyer, MatteReuseLeavesNothingStale) {
  KeyScene scene(SceneOptions{});
  ChromaKeyer keyer;
  keyer.Train(EmptyFrames(scene, 4));
  Matte m;
  keyer.Key(scene.Render({HamsterAt({150, 150})}, 1).bgr, m);
  const SceneFrame second = scene.Render({HamsterAt({480, 330})}, 2);
  keyer.Key(second.bgr, m);
  EXPECT_GE(SoftIoU(second.alpha, m.alpha), 0.95);
  EXPECT_EQ(cv::countNonZero(m.alpha(cv::Rect(60, 80, 180, 160))), 0);
  EXPECT_EQ(cv::countNonZero(m.shadow(cv::Rect(60, 80, 180, 160))), 0);
}

TEST(ChromaKeyer, FramesOfOtherPixelFormatsKeyAlike) {
  KeyScene scene(SceneOptions{});
  ChromaKeyer keyer;
  keyer.Train(EmptyFrames(scene, 4));
  const SceneFrame f = scene.Render({HamsterAt({300, 220})}, 1);
  Matte direct, via_bgr, via_rgb;
  keyer.Key(f.bgr, direct);
  const std::vector<uint8_t> bgr_bytes(f.bgr.data, f.bgr.data + f.bgr.total() * 3);
  cv::Mat rgb;
  cv::cvtColor(f.bgr, rgb, cv::COLOR_BGR2RGB);
  const std::vector<uint8_t> rgb_bytes(rgb.data, rgb.data + rgb.total() * 3);
  cv::Mat scratch;
  keyer.Key(Frame::Owned(PixelFormat::kBGR8, 640, 480, bgr_bytes), scratch, via_bgr);
  keyer.Key(Frame::Owned(PixelFormat::kRGB8, 640, 480, rgb_bytes), scratch, via_rgb);
  EXPECT_EQ(cv::norm(direct.alpha, via_bgr.alpha, cv::NORM_INF), 0);
  EXPECT_EQ(cv::norm(direct.alpha, via_rgb.alpha, cv::NORM_INF), 0);
}

// `bgr` as a camera delivering `format` would send it (OpenCV's BT.601
// conventions, which core/frame.h ToBgr inverts).
Frame AsFormat(const cv::Mat& bgr, PixelFormat format) {
  const int w = bgr.cols, h = bgr.rows;
  std::vector<uint8_t> bytes;
  if (format == PixelFormat::kBayerRG8) {  // R G / G B
    bytes.resize(static_cast<size_t>(w) * h);
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        const int channel = (y % 2 == 0 && x % 2 == 0) ? 2 : (y % 2 == 1 && x % 2 == 1) ? 0 : 1;
        bytes[static_cast<size_t>(y) * w + x] = bgr.at<cv::Vec3b>(y, x)[channel];
      }
    }
  } else if (format == PixelFormat::kNV12 || format == PixelFormat::kYUYV) {
    cv::Mat i420;  // Y plane, then U and V at half resolution
    cv::cvtColor(bgr, i420, cv::COLOR_BGR2YUV_I420);
    const uint8_t* yp = i420.data;
    const uint8_t* up = yp + static_cast<size_t>(w) * h;
    const uint8_t* vp = up + static_cast<size_t>(w / 2) * (h / 2);
    if (format == PixelFormat::kNV12) {
      bytes.assign(yp, yp + static_cast<size_t>(w) * h);
      for (size_t i = 0; i < static_cast<size_t>(w / 2) * (h / 2); ++i) {
        bytes.push_back(up[i]);
        bytes.push_back(vp[i]);
      }
    } else {  // Y0 U Y1 V, chroma shared by two rows here
      for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; x += 2) {
          const size_t c = static_cast<size_t>(y / 2) * (w / 2) + x / 2;
          bytes.insert(bytes.end(), {yp[static_cast<size_t>(y) * w + x], up[c],
                                     yp[static_cast<size_t>(y) * w + x + 1], vp[c]});
        }
      }
    }
  } else if (format == PixelFormat::kMono8) {
    cv::Mat grey;
    cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
    bytes.assign(grey.data, grey.data + grey.total());
  }
  return Frame::Owned(format, w, h, std::move(bytes));
}

// Bayer, NV12 and YUYV frames (training frames delivered alike) key close to
// the truth; the chroma subsampling and the demosaic soften only the edge.
TEST(ChromaKeyer, BayerAndYuvFramesKeyCloseToTruth) {
  KeyScene scene(SceneOptions{});
  const SceneFrame f = scene.Render({HamsterAt({300.5, 220.5})}, 1);
  for (PixelFormat format : {PixelFormat::kBayerRG8, PixelFormat::kNV12, PixelFormat::kYUYV}) {
    std::vector<cv::Mat> empty;
    empty.reserve(4);
    for (int i = 0; i < 4; ++i) empty.push_back(ToBgr(AsFormat(scene.Empty(1000 + i), format)));
    ChromaKeyer keyer;
    keyer.Train(empty);
    Matte m;
    cv::Mat scratch;
    keyer.Key(AsFormat(f.bgr, format), scratch, m);
    EXPECT_GE(SoftIoU(f.alpha, m.alpha), 0.9) << PixelFormatName(format);
    EXPECT_GE(BinaryIoU(f.alpha, m.alpha), 0.95) << PixelFormatName(format);
    EXPECT_EQ(StrayAlpha(f, m.alpha, 3), 0) << PixelFormatName(format);
  }
}

TEST(ChromaKeyer, MonoAndMalformedFramesAreClearErrors) {
  KeyScene scene(SceneOptions{});
  ChromaKeyer keyer;
  keyer.Train(EmptyFrames(scene, 2));
  Matte m;
  cv::Mat scratch;
  const cv::Mat bgr = scene.Render({HamsterAt({300, 220})}, 1).bgr;
  try {
    keyer.Key(AsFormat(bgr, PixelFormat::kMono8), scratch, m);
    ADD_FAILURE() << "a mono8 frame was chroma keyed";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("mono8"), std::string::npos) << e.what();
  }
  Frame short_frame = AsFormat(bgr, PixelFormat::kNV12);
  short_frame.size /= 2;
  EXPECT_THROW(keyer.Key(short_frame, scratch, m), InputError);
  Frame unknown = AsFormat(bgr, PixelFormat::kNV12);
  unknown.format = static_cast<PixelFormat>(99);
  EXPECT_THROW(keyer.Key(unknown, scratch, m), InputError);
  // Nor can the clean-plate keyer: in grey, a darker subject is a shadow.
  CleanPlateKeyer plate;
  plate.Train(EmptyFrames(scene, 2));
  EXPECT_THROW(plate.Key(AsFormat(bgr, PixelFormat::kMono8), scratch, m), InputError);
}

TEST(ChromaKeyer, RefusesBadInput) {
  ChromaKeyer keyer;
  Matte m;
  EXPECT_THROW(keyer.Key(cv::Mat(480, 640, CV_8UC3, cv::Scalar(60, 170, 50)), m), WorkError);
  EXPECT_THROW(keyer.Train({}), InputError);
  EXPECT_THROW(keyer.Train({cv::Mat(480, 640, CV_8UC1, cv::Scalar(0))}), InputError);
  EXPECT_THROW(keyer.Train({cv::Mat(480, 640, CV_8UC3), cv::Mat(240, 320, CV_8UC3)}), InputError);
  // A grey enclosure is not a green screen.
  EXPECT_THROW(keyer.Train({cv::Mat(480, 640, CV_8UC3, cv::Scalar(120, 120, 120))}), InputError);
  keyer.Train({cv::Mat(480, 640, CV_8UC3, cv::Scalar(60, 170, 50))});
  EXPECT_THROW(keyer.Key(cv::Mat(240, 320, CV_8UC3, cv::Scalar(60, 170, 50)), m), InputError);
  EXPECT_THROW(keyer.Key(cv::Mat(480, 640, CV_8UC4, cv::Scalar(60, 170, 50, 0)), m), InputError);
  ChromaKeyerOptions bad;
  bad.grid.step = 0;
  EXPECT_THROW(ChromaKeyer{bad}, InputError);
}

TEST(CleanPlateKeyer, KeysOnATexturedNonGreenFloor) {
  SceneOptions carpet;
  carpet.green = false;
  KeyScene scene(carpet);
  CleanPlateKeyer keyer;
  keyer.Train(EmptyFrames(scene, 8));
  ChromaKeyer chroma;
  EXPECT_THROW(chroma.Train(EmptyFrames(scene, 2)), InputError);

  for (const cv::Point2d c : {cv::Point2d(320.3, 240.6), cv::Point2d(120.5, 330.2)}) {
    SceneSubject s = HamsterAt(c);
    s.spill = 0;
    const SceneFrame f = scene.Render({s}, 1);
    Matte m;
    keyer.Key(f.bgr, m);
    EXPECT_GE(SoftIoU(f.alpha, m.alpha), 0.95) << "subject at " << c;
    EXPECT_GE(BinaryIoU(f.alpha, m.alpha), 0.97) << "subject at " << c;
    EXPECT_EQ(StrayAlpha(f, m.alpha, 3), 0) << "subject at " << c;

    const cv::Mat off_subject = f.alpha == 0;
    const cv::Mat in_shadow = (f.darkening > 0.15) & off_subject;
    const cv::Mat no_shadow = (f.darkening < 0.01) & off_subject;
    EXPECT_NEAR(MeanOver(m.shadow, in_shadow), cv::mean(f.darkening, in_shadow)[0], 0.05);
    EXPECT_LT(MeanOver(m.shadow, no_shadow), 0.005);
    EXPECT_LT(MeanOver(m.alpha, in_shadow), 0.02);
  }
  Matte m;
  keyer.Key(scene.Empty(5), m);
  EXPECT_TRUE(m.regions.empty());
}

}  // namespace
}  // namespace ss
