// The chroma keyer against the synthetic studio's truth (synth/): an animal
// walking in the green enclosure, seen through a real lens with vignetting,
// per-channel gains and sensor noise, the grey room behind the walls in view.
// The keyer is trained on the clean plate through the same sensor, as a
// station is trained on its empty enclosure.
#include <algorithm>
#include <memory>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "core/frame.h"
#include "pipeline/extract/extractor.h"
#include "pipeline/key/chroma_keyer.h"
#include "pipeline/run/camera_pipeline.h"
#include "synth/directors.h"
#include "synth/renderer.h"
#include "synth/scene.h"
#include "tests/pipeline/key_scene.h"
#include "tests/pipeline/synth_clean_plate.h"

namespace ss {
namespace {

constexpr int kWidth = 640;
constexpr int kHeight = 480;

struct KeyedFrame {
  double soft_iou = 0;
  int candidates = 0;
  double visible_px = 0;
};

// Renders `frames` frames (every `stride`-th of a 30 fps session) of one animal
// for one camera, keys them as `format` and scores each against the truth.
std::vector<KeyedFrame> KeySynthSession(uint64_t seed, PixelFormat format, int frames, int stride,
                                        const ChromaKeyerOptions& keyer_options = {}) {
  using namespace synth;
  const Studio studio = MakeStudio(StudioKind::kEnclosure, seed);
  const std::vector<SynthCamera> cameras = MakeCameras(studio, 1, kWidth, kHeight, seed);
  const CameraRenderer renderer(cameras[0], studio);
  const Sensor sensor(seed, 0, 1.0);

  cv::Mat scratch;
  ChromaKeyer keyer(keyer_options);
  keyer.Train(testing::CleanPlateFrames(renderer, sensor, format));
  Extractor extractor;

  DirectorOptions options;
  options.subjects = 1;
  options.seed = seed;
  std::unique_ptr<Director> director = MakeAnimalDirector(studio, cameras, options);
  FrameSnapshot snap;
  CameraImage image;
  Matte matte;
  std::vector<KeyedFrame> out;
  for (int i = 0; i < frames; ++i) {
    const int frame = i * stride;
    director->Frame(frame / 30.0, &snap);
    renderer.Render(snap.scene, &image);
    const Frame f = Frame::Owned(format, kWidth, kHeight,
                                 sensor.Capture(image.bgr, format, static_cast<uint64_t>(frame)));
    keyer.Key(f, scratch, matte);
    cv::Mat truth = cv::Mat::zeros(kHeight, kWidth, CV_32F);
    for (const MatteLayer& layer : image.alpha) {
      if (layer.box.empty()) continue;
      cv::Mat a;
      layer.values.convertTo(a, CV_32F, 1.0 / 255);
      cv::Mat roi = truth(layer.box);
      cv::max(roi, a, roi);
    }
    KeyedFrame k;
    k.soft_iou = testing::SoftIoU(truth, matte.alpha);
    k.candidates = static_cast<int>(extractor.Extract(matte).size());
    k.visible_px = image.visible_px.empty() ? 0 : image.visible_px[0];
    out.push_back(k);
  }
  return out;
}

double MedianIoU(const std::vector<KeyedFrame>& frames, double min_visible_px) {
  std::vector<double> v;
  for (const KeyedFrame& f : frames) {
    if (f.visible_px >= min_visible_px) v.push_back(f.soft_iou);
  }
  if (v.empty()) return 0;
  std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

TEST(KeySynth, MedianAlphaIoUOnAStudioSessionRgb) {
  const std::vector<KeyedFrame> frames = KeySynthSession(3, PixelFormat::kRGB8, 16, 7);
  int seen = 0, single = 0;
  for (const KeyedFrame& f : frames) {
    if (f.visible_px < 200) continue;
    ++seen;
    single += f.candidates == 1;
  }
  ASSERT_GE(seen, 12) << "the animal should be in view in most frames";
  RecordProperty("median_iou", std::to_string(MedianIoU(frames, 200)));
  EXPECT_GE(MedianIoU(frames, 200), 0.95);
  // One candidate for the one animal: no stray regions from the walls or the room.
  EXPECT_GE(single, seen - 1);
}

TEST(KeySynth, MedianAlphaIoUOnAStudioSessionBayer) {
  const std::vector<KeyedFrame> frames = KeySynthSession(5, PixelFormat::kBayerRG8, 10, 11);
  EXPECT_GE(MedianIoU(frames, 200), 0.9);
}

// The keyer as the station's default config sets it up (ChromaKeyerOptionsFrom: chroma
// low/high in levels, shadow thresholds, despill) keys the studio as well as the keyer's defaults.
TEST(KeySynth, MedianAlphaIoUWithTheStationConfigDefaults) {
  const ChromaKeyerOptions options = ChromaKeyerOptionsFrom(KeyingConfig{});
  const std::vector<KeyedFrame> frames = KeySynthSession(3, PixelFormat::kRGB8, 16, 7, options);
  const double iou = MedianIoU(frames, 200);
  RecordProperty("median_iou", std::to_string(iou));
  EXPECT_GE(iou, 0.95);
}

}  // namespace
}  // namespace ss
