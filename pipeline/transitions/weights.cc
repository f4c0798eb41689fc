#include "pipeline/transitions/weights.h"

#include <array>
#include <cmath>
#include <fstream>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/option_checks.h"

namespace ss {

namespace {

using nlohmann::json;

// Reads one field, naming it (dotted path) in every error.
class FieldReader {
 public:
  FieldReader(const json& root, std::string source) : root_(root), source_(std::move(source)) {}

  [[noreturn]] void Fail(const std::string& field, const std::string& reason) const {
    throw InputError(source_, field + ": " + reason);
  }
  const json& Get(const std::string& field) const {
    const json* node = &root_;
    std::string::size_type start = 0;
    while (true) {
      const auto dot = field.find('.', start);
      const std::string key =
          field.substr(start, dot == std::string::npos ? std::string::npos : dot - start);
      if (!node->is_object() || !node->contains(key)) Fail(field, "missing");
      node = &(*node)[key];
      if (dot == std::string::npos) return *node;
      start = dot + 1;
    }
  }
  double Number(const std::string& field) const {
    const json& v = Get(field);
    if (!v.is_number()) Fail(field, "expected a number, got " + v.dump());
    const double x = v.get<double>();
    if (!std::isfinite(x)) Fail(field, "expected a finite number");
    return x;
  }
  int Integer(const std::string& field) const {
    const json& v = Get(field);
    if (!v.is_number_integer()) Fail(field, "expected an integer, got " + v.dump());
    return v.get<int>();
  }
  template <size_t N>
  std::array<double, N> Numbers(const std::string& field) const {
    const json& v = Get(field);
    if (!v.is_array() || v.size() != N) {
      Fail(field, "expected an array of " + std::to_string(N) + " numbers, got " + v.dump());
    }
    std::array<double, N> out{};
    for (size_t k = 0; k < N; ++k) {
      if (!v[k].is_number() || !std::isfinite(v[k].get<double>())) {
        Fail(field, "element " + std::to_string(k) + " is not a finite number: " + v[k].dump());
      }
      out[k] = v[k].get<double>();
    }
    return out;
  }

 private:
  const json& root_;
  std::string source_;
};

// The elements of `values` that `good` refuses, "element K is V" each, joined by ", ".
template <size_t N, class Good>
std::string BadElements(const std::array<double, N>& values, Good good) {
  std::string out;
  for (size_t k = 0; k < N; ++k) {
    if (good(values[k])) continue;
    out += (out.empty() ? "" : ", ") + std::string("element ") + std::to_string(k) + " is " +
           OptionProblems::Num(values[k]);
  }
  return out;
}

}  // namespace

bool TransitionWeights::IsValid(std::string* why) const {
  OptionProblems check(why);
  std::string part;
  check.Nested(window.IsValid(&part), "comparison_window.", part);
  const auto positive = [](double v) { return std::isfinite(v) && v > 0; };
  const auto non_negative = [](double v) { return std::isfinite(v) && v >= 0; };
  const auto finite = [](double v) { return std::isfinite(v); };
  std::string bad = BadElements(feature_mean, finite);
  check(bad.empty(), "feature_mean", "expected finite numbers, but " + bad);
  bad = BadElements(feature_scale, positive);
  check(bad.empty(), "feature_scale", "expected positive numbers, but " + bad);
  bad = BadElements(stage1_weights, non_negative);
  check(bad.empty(), "stage1.weights",
        "expected numbers >= 0 (stage 1 must accept a weighted-L1 ball), but " + bad);
  check(std::isfinite(stage1_bias), "stage1.bias",
        "expected a finite number, got " + OptionProblems::Num(stage1_bias));
  bad = BadElements(stage2_weights, non_negative);
  check(bad.empty(), "stage2.weights", "expected numbers >= 0, but " + bad);
  check(std::isfinite(stage2_bias), "stage2.bias",
        "expected a finite number, got " + OptionProblems::Num(stage2_bias));
  if (stage2_variant == Stage2Variant::kLinf) {
    check(positive(linf_max_velocity_mps), "stage2.linf.max_velocity_mps",
          "expected a positive number, got " + OptionProblems::Num(linf_max_velocity_mps));
    check.Within(linf_max_alpha, AboveUpTo(0, 1), "stage2.linf.max_alpha_linf",
                 "a number in (0, 1]");
  }
  if (stage2_variant == Stage2Variant::kColourBlob) {
    check(positive(colour_blob_max_velocity_mps), "stage2.colour_blob.max_velocity_mps",
          "expected a positive number, got " + OptionProblems::Num(colour_blob_max_velocity_mps));
    check.Within(colour_blob_max_cells, AtLeast(0), "stage2.colour_blob.max_blob_cells",
                 "a number >= 0");
  }
  if (stage2_variant == Stage2Variant::kColourCells) {
    check(positive(colour_cells_max_velocity_mps), "stage2.colour_cells.max_velocity_mps",
          "expected a positive number, got " + OptionProblems::Num(colour_cells_max_velocity_mps));
    // 255 * the bound must fit the integer sums it is compared with.
    check(non_negative(colour_cells_max_alpha_cells) && colour_cells_max_alpha_cells <= 1e12,
          "stage2.colour_cells.max_alpha_cells",
          "expected a number from 0 to 1e12, got " +
              OptionProblems::Num(colour_cells_max_alpha_cells));
    check.Within(colour_cells_max_cells, AtLeast(0), "stage2.colour_cells.max_colour_cells",
                 "a number >= 0");
  }
  return check.ok();
}

TransitionWeights ParseWeights(const std::string& text, const std::string& source) {
  json root;
  try {
    root = json::parse(text);
  } catch (const json::exception& e) {  // parse errors, and numbers out of range (tests/fuzz)
    throw InputError(source, std::string("not valid JSON: ") + e.what());
  }
  if (!root.is_object()) throw InputError(source, "expected a JSON object at the top level");
  FieldReader r(root, source);
  const json& format = r.Get("format");
  if (!format.is_string() || format.get<std::string>() != kWeightsFileFormat) {
    r.Fail("format", std::string("expected \"") + kWeightsFileFormat + "\", got " + format.dump());
  }
  const int version = r.Integer("version");
  if (version < 1 || version > kWeightsFileVersion) {
    r.Fail("version", "this build reads versions 1 to " + std::to_string(kWeightsFileVersion) +
                          ", the file has " + std::to_string(version));
  }
  const json& names = r.Get("features");
  json expected = json::array();
  for (const auto& n : FeatureNames()) expected.push_back(n);
  if (names != expected)
    r.Fail("features", "expected " + expected.dump() + ", got " + names.dump());

  TransitionWeights w;
  w.window.width_m = r.Number("comparison_window.width_m");
  w.window.height_m = r.Number("comparison_window.height_m");
  w.window.cells_x = r.Integer("comparison_window.cells_x");
  w.window.cells_y = r.Integer("comparison_window.cells_y");
  const json& align = r.Get("comparison_window.align");
  if (align == "alpha_centroid") {
    w.window.align = HorizontalAlignment::kAlphaCentroid;
  } else if (align == "contact_point") {
    w.window.align = HorizontalAlignment::kContactPoint;
  } else {
    r.Fail("comparison_window.align",
           "expected \"alpha_centroid\" or \"contact_point\", got " + align.dump());
  }
  w.feature_mean = r.Numbers<kPairFeatureCount>("feature_mean");
  w.feature_scale = r.Numbers<kPairFeatureCount>("feature_scale");
  w.stage1_weights = r.Numbers<kCheapFeatureCount>("stage1.weights");
  w.stage1_bias = r.Number("stage1.bias");
  w.stage2_weights = r.Numbers<kPairFeatureCount>("stage2.weights");
  w.stage2_bias = r.Number("stage2.bias");
  if (version < 2 && r.Get("stage2").contains("variant")) {
    r.Fail("stage2.variant", "needs version 2 (version 1 files are the paper's variant)");
  }
  if (version >= 2) {
    const json& variant = r.Get("stage2.variant");
    if (variant == "paper") {
      w.stage2_variant = Stage2Variant::kPaper;
    } else if (variant == "linf") {
      w.stage2_variant = Stage2Variant::kLinf;
      w.linf_max_velocity_mps = r.Number("stage2.linf.max_velocity_mps");
      w.linf_max_alpha = r.Number("stage2.linf.max_alpha_linf");
    } else if (variant == "colour_blob") {
      w.stage2_variant = Stage2Variant::kColourBlob;
      w.colour_blob_max_velocity_mps = r.Number("stage2.colour_blob.max_velocity_mps");
      w.colour_blob_max_cells = r.Integer("stage2.colour_blob.max_blob_cells");
    } else if (variant == "colour_cells") {
      w.stage2_variant = Stage2Variant::kColourCells;
      w.colour_cells_max_velocity_mps = r.Number("stage2.colour_cells.max_velocity_mps");
      w.colour_cells_max_alpha_cells = r.Number("stage2.colour_cells.max_alpha_cells");
      w.colour_cells_max_cells = r.Integer("stage2.colour_cells.max_colour_cells");
    } else {
      r.Fail("stage2.variant",
             "expected \"paper\", \"linf\", \"colour_blob\" or \"colour_cells\", got " +
                 variant.dump());
    }
  }
  if (root.contains("training")) {
    if (!root["training"].is_object()) r.Fail("training", "expected an object");
    w.training_json = root["training"].dump();
  }
  std::string why;
  if (!w.IsValid(&why)) throw InputError(source, why);
  return w;
}

TransitionWeights LoadWeights(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, "cannot open the weights file");
  std::stringstream buffer;
  buffer << in.rdbuf();
  if (in.bad()) throw InputError(path, "cannot read the weights file");
  return ParseWeights(buffer.str(), path);
}

std::string WeightsToJson(const TransitionWeights& w) {
  json root;
  root["format"] = kWeightsFileFormat;
  const bool linf = w.stage2_variant == Stage2Variant::kLinf;
  const bool blob = w.stage2_variant == Stage2Variant::kColourBlob;
  const bool cells = w.stage2_variant == Stage2Variant::kColourCells;
  root["version"] = linf || blob || cells ? 2 : 1;  // the paper variant is written as version 1 was
  root["features"] = FeatureNames();
  root["comparison_window"] = {
      {"width_m", w.window.width_m},
      {"height_m", w.window.height_m},
      {"cells_x", w.window.cells_x},
      {"cells_y", w.window.cells_y},
      {"align",
       w.window.align == HorizontalAlignment::kAlphaCentroid ? "alpha_centroid" : "contact_point"}};
  root["feature_mean"] = w.feature_mean;
  root["feature_scale"] = w.feature_scale;
  root["stage1"] = {{"weights", w.stage1_weights}, {"bias", w.stage1_bias}};
  root["stage2"] = {{"weights", w.stage2_weights}, {"bias", w.stage2_bias}};
  if (linf) {
    root["stage2"]["variant"] = "linf";
    root["stage2"]["linf"] = {{"max_velocity_mps", w.linf_max_velocity_mps},
                              {"max_alpha_linf", w.linf_max_alpha}};
  }
  if (blob) {
    root["stage2"]["variant"] = "colour_blob";
    root["stage2"]["colour_blob"] = {{"max_velocity_mps", w.colour_blob_max_velocity_mps},
                                     {"max_blob_cells", w.colour_blob_max_cells}};
  }
  if (cells) {
    root["stage2"]["variant"] = "colour_cells";
    root["stage2"]["colour_cells"] = {{"max_velocity_mps", w.colour_cells_max_velocity_mps},
                                      {"max_alpha_cells", w.colour_cells_max_alpha_cells},
                                      {"max_colour_cells", w.colour_cells_max_cells}};
  }
  json training = json::parse(w.training_json, nullptr, false);
  root["training"] = training.is_object() ? training : json::object();
  return root.dump(2) + "\n";
}

void SaveWeights(const TransitionWeights& w, const std::string& path) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw WorkError(path, "cannot open for writing");
  out << WeightsToJson(w);
  out.close();
  if (!out) throw WorkError(path, "write failed");
}

const TransitionWeights& DefaultWeights() {
  static const TransitionWeights weights =
      ParseWeights(DefaultWeightsText(), "pipeline/transitions/default_weights.json (built in)");
  return weights;
}

const TransitionWeights& PaperWeights() {
  static const TransitionWeights weights =
      ParseWeights(PaperWeightsText(), "pipeline/transitions/paper_weights.json (built in)");
  return weights;
}

const TransitionWeights& ColourCellsWeights() {
  static const TransitionWeights weights = ParseWeights(
      ColourCellsWeightsText(), "pipeline/transitions/colour_cells_weights.json (built in)");
  return weights;
}

}  // namespace ss
