// Each pipeline component's options: the defaults are valid, a value out of range is refused
// naming its field, and the component's entry point refuses it with an InputError.
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/error.h"
#include "pipeline/extract/extractor.h"
#include "pipeline/key/chroma_keyer.h"
#include "pipeline/rectify/rectifier.h"
#include "pipeline/run/clip_batcher.h"
#include "pipeline/run/ingest.h"
#include "pipeline/track/tracker.h"
#include "pipeline/transitions/bank_training.h"
#include "pipeline/transitions/bank_transitions.h"
#include "pipeline/transitions/builder.h"
#include "pipeline/transitions/classifier.h"
#include "pipeline/transitions/comparison.h"
#include "pipeline/transitions/synthetic.h"
#include "pipeline/transitions/training.h"
#include "pipeline/transitions/truth_labels.h"
#include "pipeline/transitions/unit_worker.h"
#include "pipeline/transitions/weights.h"
#include "tests/support/error_text.h"
#include "tests/support/option_problems.h"

namespace ss {
namespace {

using testing::InputErrorOf;
using testing::Names;
using testing::Problems;

TEST(PipelineOptions, DefaultsAreValid) {
  EXPECT_EQ(Problems(GridOptions{}), "");
  EXPECT_EQ(Problems(ExtractorOptions{}), "");
  EXPECT_EQ(Problems(RectifierOptions{}), "");
  EXPECT_EQ(Problems(SyntheticSpriteOptions{}), "");
  EXPECT_EQ(Problems(LogisticOptions{}), "");
  EXPECT_EQ(Problems(TrainOptions{}), "");
  EXPECT_EQ(Problems(BankUpdateOptions{}), "");
  EXPECT_EQ(Problems(TruthLabelOptions{}), "");
  EXPECT_EQ(Problems(BankTrainOptions{}), "");
  EXPECT_EQ(Problems(BuildOptions{}), "");
  EXPECT_EQ(Problems(UnitWorkerOptions{}), "");
  EXPECT_EQ(Problems(IngestOptions{}), "");
  EXPECT_EQ(Problems(SideBySideOptions{}), "");
  EXPECT_EQ(Problems(ComparisonWindow{}), "");
  EXPECT_EQ(Problems(TransitionWeights{}), "");
  EXPECT_EQ(Problems(DefaultWeights()), "");
}

TEST(PipelineOptions, GridAndKeyer) {
  GridOptions g;
  g.step = 65;
  EXPECT_TRUE(Names(Problems(g), "step"));
  g = {};
  g.margin_px = -1;
  g.shadow_reach_cells = -1;
  const std::string why = Problems(g);
  EXPECT_TRUE(Names(why, "margin_px")) << why;
  EXPECT_TRUE(Names(why, "shadow_reach_cells")) << why;
  ChromaKeyerOptions bad;
  bad.grid.step = 1;
  const std::string what = InputErrorOf([&] { ChromaKeyer keyer(bad); });
  EXPECT_EQ(what.rfind("keyer grid options: step: ", 0), 0u) << what;
}

// The tracker and the clip batcher check their options themselves, not only inside a
// CameraPipeline (the batcher used to raise a negative velocity window to 0 without a word).
TEST(PipelineOptions, TrackerAndClipBatcherRefuseBadOptions) {
  TrackerOptions t;
  t.max_speed_m_per_s = 0;
  EXPECT_EQ(
      InputErrorOf([&] { Tracker tracker(t); }).rfind("tracker options: max_speed_m_per_s: ", 0),
      0u);
  ClipBatcherOptions b;
  b.velocity_half_window = -1;
  const std::string what = InputErrorOf([&] { ClipBatcher batcher(1, b); });
  EXPECT_EQ(what.rfind("clip batcher options: velocity_half_window: ", 0), 0u) << what;
  EXPECT_NO_THROW(Tracker{});
  EXPECT_NO_THROW(ClipBatcher(1, ClipBatcherOptions{}));
}

TEST(PipelineOptions, ExtractorNestsTheContactPoint) {
  ExtractorOptions o;
  o.contact.min_band_px = 0;
  EXPECT_TRUE(Names(Problems(o), "contact.min_band_px"));
  const std::string what = InputErrorOf([&] { Extractor extractor(o); });
  EXPECT_EQ(what, "extract options: " + Problems(o)) << what;
  o = {};
  o.min_area = -1;
  EXPECT_NE(InputErrorOf([&] { Extractor extractor(o); }).find("min_area: "), std::string::npos);
}

TEST(PipelineOptions, Rectifier) {
  RectifierOptions o;
  o.px_per_m = 0;
  EXPECT_TRUE(Names(Problems(o), "px_per_m"));
  o = {};
  o.margin_m = -0.01;
  o.max_side_px = 2;
  const std::string why = Problems(o);
  EXPECT_TRUE(Names(why, "margin_m")) << why;
  EXPECT_TRUE(Names(why, "max_side_px")) << why;
  o = {};
  o.shadow_radius_m = std::nan("");
  const std::string what = InputErrorOf([&] { Rectifier rectifier(o); });
  EXPECT_EQ(what.rfind("rectifier options: shadow_radius_m: ", 0), 0u) << what;
}

TEST(PipelineOptions, CameraPipelineNestsTheRectifierButLeavesAutoScale) {
  CameraPipelineOptions o;
  o.rectify.px_per_m = 0;  // auto: the caller resolves it
  EXPECT_EQ(Problems(o), "");
  o.rectify.max_side_px = 0;
  EXPECT_TRUE(Names(Problems(o), "rectify.max_side_px"));
  o.side_by_side.min_part_share = 0.7;
  EXPECT_TRUE(Names(Problems(o), "side_by_side.min_part_share"));
}

TEST(PipelineOptions, SyntheticSprites) {
  SyntheticSpriteOptions o;
  o.min_clip_frames = 0;
  EXPECT_TRUE(Names(Problems(o), "min_clip_frames"));
  o = {};
  o.max_clip_frames = o.min_clip_frames - 1;
  o.pixel_noise = -1;
  const std::string why = Problems(o);
  EXPECT_TRUE(Names(why, "max_clip_frames")) << why;
  EXPECT_TRUE(Names(why, "pixel_noise")) << why;
  o = {};
  o.frames = 10;
  o.fps = 0;
  const std::string what = InputErrorOf([&] { MakeSyntheticSprites(o); });
  EXPECT_EQ(what.rfind("synthetic sprite options: fps: ", 0), 0u) << what;
}

TEST(PipelineOptions, Training) {
  LogisticOptions l;
  l.l2 = -1;
  EXPECT_TRUE(Names(Problems(l), "l2"));
  l = {};
  l.max_iterations = 0;
  EXPECT_TRUE(Names(Problems(l), "max_iterations"));
  TrainOptions t;
  t.folds = 1;
  t.logistic.tolerance = -1;
  const std::string why = Problems(t);
  EXPECT_TRUE(Names(why, "folds")) << why;
  EXPECT_TRUE(Names(why, "logistic.tolerance")) << why;
  // Refused before the features are looked at.
  const std::string what =
      InputErrorOf([&] { TrainWeights({}, {}, ComparisonWindow{}, t, nullptr); });
  EXPECT_EQ(what.rfind("training options: folds: ", 0), 0u) << what;
  const std::string fit = InputErrorOf([&] { FitLogistic({}, 1, {}, l); });
  EXPECT_EQ(fit.rfind("logistic options: max_iterations: ", 0), 0u) << fit;
}

TEST(PipelineOptions, TruthLabels) {
  TruthLabelOptions o;
  o.near_miss_fraction = 1.5;
  EXPECT_TRUE(Names(Problems(o), "near_miss_fraction"));
  o = {};
  o.max_phase_difference = -0.1;
  o.near_miss_factor = 0.5;
  const std::string why = Problems(o);
  EXPECT_TRUE(Names(why, "max_phase_difference")) << why;
  EXPECT_TRUE(Names(why, "near_miss_factor")) << why;
  const std::vector<int64_t> ids = {1, 2};
  const std::vector<SpriteTruth> truth(2);
  const std::string what = InputErrorOf([&] { LabelsFromTruth(ids, truth, 2, o, 1); });
  EXPECT_EQ(what.rfind("truth label options: max_phase_difference: ", 0), 0u) << what;
}

TEST(PipelineOptions, BankTraining) {
  BankTrainOptions o;
  o.stage1_recall = 1.5;
  o.train.folds = 0;
  std::string why = Problems(o);
  EXPECT_TRUE(Names(why, "stage1_recall")) << why;
  EXPECT_TRUE(Names(why, "train.folds")) << why;
  o = {};
  o.positive_rate = -1;  // the labels file's
  EXPECT_EQ(Problems(o), "");
  o.positive_rate = 2;
  o.calibration_rows = 0;
  o.window.cells_x = 0;
  why = Problems(o);
  EXPECT_TRUE(Names(why, "positive_rate")) << why;
  EXPECT_TRUE(Names(why, "calibration_rows")) << why;
  EXPECT_TRUE(Names(why, "window.cells_x")) << why;
  // Refused before the files are read.
  o = {};
  o.threads = 0;
  const std::string what = InputErrorOf([&] { TrainOnBank("/no/labels.csv", "/no/bank", o); });
  EXPECT_EQ(what.rfind("training options: threads: ", 0), 0u) << what;
}

TEST(PipelineOptions, TransitionBuildersAndWorkers) {
  BuildOptions b;
  b.threads = 0;
  EXPECT_TRUE(Names(Problems(b), "threads"));
  TransitionBuilder builder(DefaultWeights(), 250);
  const std::string built = InputErrorOf([&] { builder.BuildFromScratch({}, b); });
  EXPECT_EQ(built.rfind("build options: threads: ", 0), 0u) << built;

  BankUpdateOptions u;
  u.weights.feature_scale[0] = 0;
  u.threads = 0;
  const std::string why = Problems(u);
  EXPECT_TRUE(Names(why, "weights.feature_scale")) << why;
  EXPECT_TRUE(Names(why, "threads")) << why;
  // Refused before the bank is opened.
  const std::string what = InputErrorOf([&] { UpdateBankTransitions("/no/bank", u); });
  EXPECT_EQ(what.rfind("transition update options: weights.feature_scale: ", 0), 0u) << what;

  UnitWorkerOptions w;
  w.lease_s = 0;
  w.load_threads = 0;
  const std::string worker = Problems(w);
  EXPECT_TRUE(Names(worker, "lease_s")) << worker;
  EXPECT_TRUE(Names(worker, "load_threads")) << worker;
}

TEST(PipelineOptions, IngestNestsThePipeline) {
  IngestOptions o;
  o.decode_threads = -1;
  o.pipeline.rectify.margin_m = -1;
  const std::string why = Problems(o);
  EXPECT_TRUE(Names(why, "decode_threads")) << why;
  EXPECT_TRUE(Names(why, "pipeline.rectify.margin_m")) << why;
  // Refused before the session is opened.
  o.session_dir = "/no/session";
  const std::string what = InputErrorOf([&] { IngestSession(o); });
  EXPECT_EQ(what.rfind("ingest options: ", 0), 0u) << what;
  EXPECT_NE(what.find("decode_threads: "), std::string::npos) << what;
}

TEST(PipelineOptions, ComparisonWindow) {
  ComparisonWindow w;
  w.width_m = 0;
  w.height_m = std::nan("");
  w.cells_x = 0;
  w.cells_y = -1;
  EXPECT_EQ(Problems(w),
            "width_m: expected a positive number of metres, got 0\n"
            "height_m: expected a positive number of metres, got nan\n"
            "cells_x: expected at least 1 cell, got 0\n"
            "cells_y: expected at least 1 cell, got -1");
  w = {};
  w.cells_x = 128;
  w.cells_y = 64;
  EXPECT_EQ(Problems(w), "cells_y: expected cells_x * cells_y <= 4096 cells, got 128 x 64");
  w.cells_x = 1 << 20;  // the product is counted without overflowing
  w.cells_y = 1 << 12;
  EXPECT_TRUE(Names(Problems(w), "cells_y"));
  // Refused before the billboard is resampled.
  w = {};
  w.cells_x = 0;
  RgbaBillboard billboard;  // a good one, 2 x 2 opaque pixels
  billboard.width = billboard.height = 2;
  billboard.rgba.assign(16, 255);
  std::vector<uint8_t> image(ComparisonWindow{}.ImageBytes());
  const std::string what =
      InputErrorOf([&] { MakeComparisonImage(billboard, 100, w, image.data()); });
  EXPECT_EQ(what, "comparison_window: cells_x: expected at least 1 cell, got 0") << what;
}

// Every problem of the weights, each named by its key in the weights file; the window's under
// "comparison_window.".
TEST(PipelineOptions, TransitionWeights) {
  TransitionWeights w;
  w.window.width_m = -1;
  w.feature_mean[1] = std::nan("");
  w.feature_scale[0] = 0;
  w.feature_scale[3] = -2;
  w.stage1_weights[2] = -0.5;
  w.stage1_bias = INFINITY;
  w.stage2_weights[5] = -1;
  w.stage2_bias = std::nan("");
  EXPECT_EQ(Problems(w),
            "comparison_window.width_m: expected a positive number of metres, got -1\n"
            "feature_mean: expected finite numbers, but element 1 is nan\n"
            "feature_scale: expected positive numbers, but element 0 is 0, element 3 is -2\n"
            "stage1.weights: expected numbers >= 0 (stage 1 must accept a weighted-L1 ball), "
            "but element 2 is -0.5\n"
            "stage1.bias: expected a finite number, got inf\n"
            "stage2.weights: expected numbers >= 0, but element 5 is -1\n"
            "stage2.bias: expected a finite number, got nan");
  // The variants' bounds count only for their variant.
  TransitionWeights linf;
  EXPECT_EQ(Problems(linf), "");
  linf.stage2_variant = Stage2Variant::kLinf;
  linf.linf_max_alpha = 1.5;
  EXPECT_EQ(Problems(linf),
            "stage2.linf.max_velocity_mps: expected a positive number, got 0\n"
            "stage2.linf.max_alpha_linf: expected a number in (0, 1], got 1.5");
  TransitionWeights blob;
  blob.stage2_variant = Stage2Variant::kColourBlob;
  blob.colour_blob_max_velocity_mps = 1;
  blob.colour_blob_max_cells = -1;
  EXPECT_EQ(Problems(blob), "stage2.colour_blob.max_blob_cells: expected a number >= 0, got -1");
  // The classifier refuses them, and a weights file holding them names the file.
  const std::string what = InputErrorOf([&] { TransitionClassifier classifier(blob); });
  EXPECT_EQ(what,
            "transition weights: stage2.colour_blob.max_blob_cells: expected a number >= 0, got "
            "-1");
  TransitionWeights bad = DefaultWeights();
  bad.feature_scale[0] = 0;
  bad.stage2_bias = INFINITY;
  const std::string file = InputErrorOf([&] { ParseWeights(WeightsToJson(bad), "w.json"); });
  EXPECT_EQ(file.rfind("w.json: ", 0), 0u) << file;
}

}  // namespace
}  // namespace ss
