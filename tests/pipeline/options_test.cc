// Each pipeline component's options: the defaults are valid, a value out of range is refused
// naming its field, and the component's entry point refuses it with an InputError.
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/error.h"
#include "pipeline/extract/extractor.h"
#include "pipeline/key/chroma_keyer.h"
#include "pipeline/rectify/rectifier.h"
#include "pipeline/run/ingest.h"
#include "tests/support/error_text.h"

namespace ss {
namespace {

using testing::InputErrorOf;

// The problems `options` has (its IsValid's `why`), "" when it is valid.
template <typename Options>
std::string Problems(const Options& options) {
  std::string why = "stale";
  const bool ok = options.IsValid(&why);
  EXPECT_EQ(ok, why.empty()) << why;
  return why;
}

// True when `why` has a line starting "FIELD: ".
bool Names(const std::string& why, const std::string& field) {
  return why.rfind(field + ": ", 0) == 0 || why.find("\n" + field + ": ") != std::string::npos;
}

TEST(PipelineOptions, DefaultsAreValid) {
  EXPECT_EQ(Problems(GridOptions{}), "");
  EXPECT_EQ(Problems(ExtractorOptions{}), "");
  EXPECT_EQ(Problems(RectifierOptions{}), "");
  EXPECT_EQ(Problems(IngestOptions{}), "");
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

}  // namespace
}  // namespace ss
