#include "animate/skeleton/importers.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/log.h"
#include "core/option_checks.h"

namespace ss {
namespace {

namespace fs = std::filesystem;

std::vector<std::string> SplitCsvLine(std::string line) {
  if (!line.empty() && line.back() == '\r') line.pop_back();
  std::vector<std::string> cells;
  std::string cell;
  bool quoted = false;
  for (char c : line) {
    if (c == '"') {
      quoted = !quoted;
    } else if (c == ',' && !quoted) {
      cells.push_back(cell);
      cell.clear();
    } else {
      cell += c;
    }
  }
  cells.push_back(cell);
  return cells;
}

// A number, or std::nullopt for an empty or NaN cell (DeepLabCut leaves unlabelled parts empty).
std::optional<float> ParseCell(const std::string& cell, const std::string& where) {
  if (cell.empty() || cell == "nan" || cell == "NaN" || cell == "NAN") return std::nullopt;
  try {
    size_t used = 0;
    const float v = std::stof(cell, &used);
    if (used != cell.size()) throw std::invalid_argument(cell);
    if (!std::isfinite(v)) return std::nullopt;
    return v;
  } catch (const std::exception&) {
    throw InputError(where, "not a number: '" + cell + "'");
  }
}

std::optional<int64_t> ParseInteger(const std::string& text) {
  if (text.empty() ||
      !std::all_of(text.begin(), text.end(), [](char c) { return c >= '0' && c <= '9'; })) {
    return std::nullopt;
  }
  try {
    return std::stoll(text);
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

// A skeleton file is read whole (JSON) or into frames (CSV), so its size sizes the work: 64 MiB
// holds some 150,000 frames of 17 key points (83 minutes at 30 frames/s) and parses within about
// 400 MB; a larger file is refused before it is read.
constexpr uintmax_t kMaxSkeletonFileBytes = uintmax_t{64} << 20;
// Frame numbers (an image id, a row index) fit a clip's frames: at most 2^31 - 1.
constexpr int64_t kMaxFrameNumber = 2147483647;

void RefuseOversizedFile(const std::string& path) {
  std::error_code ec;
  const uintmax_t bytes = fs::file_size(path, ec);
  if (ec || bytes <= kMaxSkeletonFileBytes) return;  // (one that cannot be opened says so later)
  throw InputError(path, "holds " + std::to_string(bytes >> 20) +
                             " MiB; a skeleton file is at most 64 MiB (about 150,000 frames)");
}

int64_t CheckedFrame(const std::string& where, const char* field, int64_t frame) {
  if (frame < 0 || frame > kMaxFrameNumber) {
    throw InputError(where, std::string(field) + " " + std::to_string(frame) +
                                " is not a frame number (0.." + std::to_string(kMaxFrameNumber) +
                                ")");
  }
  return frame;
}

// A JSON integer as a frame number; one past int64_t (parsed as unsigned) is refused as such.
int64_t FrameFromJson(const std::string& where, const char* field, const nlohmann::json& value) {
  if (value.is_number_unsigned() &&
      value.get<uint64_t>() > static_cast<uint64_t>(kMaxFrameNumber)) {
    throw InputError(where, std::string(field) + " " + std::to_string(value.get<uint64_t>()) +
                                " is not a frame number (0.." + std::to_string(kMaxFrameNumber) +
                                ")");
  }
  return CheckedFrame(where, field, value.get<int64_t>());
}

nlohmann::json ReadJsonFile(const std::string& path) {
  RefuseOversizedFile(path);
  std::ifstream in(path);
  if (!in) throw InputError(path, "cannot open");
  try {
    return nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(path, std::string("not valid JSON: ") + e.what());
  }
}

SkeletonSequence NewSequence(const JointMapping& mapping, const std::string& path) {
  SkeletonSequence sequence;
  sequence.skeleton = mapping.skeleton;
  sequence.clip = fs::path(path).stem().string();
  return sequence;
}

// One column group of a DeepLabCut file: a body part's x, y and likelihood columns.
struct DlcPart {
  std::string name;
  int x = -1, y = -1, likelihood = -1;
};

void RefuseBadOptions(const SkeletonImportOptions& options) {
  if (std::string why; !options.IsValid(&why)) throw InputError("skeleton import options", why);
}

}  // namespace

bool SkeletonImportOptions::IsValid(std::string* why) const {
  OptionProblems check(why);
  check(!min_confidence || (*min_confidence >= 0 && *min_confidence <= 1), "min_confidence",
        "must be within [0, 1] (or unset: the mapping's or the format's), got " +
            OptionProblems::Num(min_confidence.value_or(0)));
  check.Within(person, AtLeast(0), "person", "an index >= 0");
  check(category_id >= -1, "category_id",
        "must be a category id >= 0 (or -1: the first with keypoints), got " +
            std::to_string(category_id));
  return check.ok();
}

SkeletonSequence ImportDeepLabCutCsv(const std::string& path, const JointMapping& mapping,
                                     const SkeletonImportOptions& options) {
  RefuseBadOptions(options);
  RefuseOversizedFile(path);
  std::ifstream in(path);
  if (!in) throw InputError(path, "cannot open the DeepLabCut CSV");
  std::vector<std::vector<std::string>> header;
  std::map<std::string, int> header_row;
  std::string line;
  int line_number = 0;
  std::vector<std::string> first_data;
  while (std::getline(in, line)) {
    ++line_number;
    auto cells = SplitCsvLine(line);
    const std::string& key = cells[0];
    if (key == "scorer" || key == "individuals" || key == "bodyparts" || key == "coords") {
      header_row[key] = static_cast<int>(header.size());
      header.push_back(std::move(cells));
      continue;
    }
    first_data = std::move(cells);
    break;
  }
  if (!header_row.count("bodyparts") || !header_row.count("coords")) {
    throw InputError(path,
                     "not a DeepLabCut CSV: the 'bodyparts' and 'coords' header rows are missing");
  }
  const auto& bodyparts = header[header_row["bodyparts"]];
  const auto& coords = header[header_row["coords"]];
  const std::vector<std::string>* individuals =
      header_row.count("individuals") ? &header[header_row["individuals"]] : nullptr;
  const size_t width = coords.size();
  for (const auto& row : header) {
    if (row.size() != width) {
      throw InputError(path, "header row '" + row[0] + "' has " + std::to_string(row.size()) +
                                 " columns, 'coords' has " + std::to_string(width));
    }
  }
  size_t leading = 1;
  while (leading < width && coords[leading] != "x" && coords[leading] != "y" &&
         coords[leading] != "likelihood") {
    ++leading;
  }
  std::string individual = options.individual;
  if (individuals && individual.empty() && leading < width) individual = (*individuals)[leading];
  std::vector<DlcPart> parts;
  for (size_t c = leading; c < width; ++c) {
    if (individuals && (*individuals)[c] != individual) continue;
    auto it = std::find_if(parts.begin(), parts.end(),
                           [&](const DlcPart& p) { return p.name == bodyparts[c]; });
    if (it == parts.end()) {
      parts.push_back({bodyparts[c]});
      it = parts.end() - 1;
    }
    const int col = static_cast<int>(c);
    if (coords[c] == "x")
      it->x = col;
    else if (coords[c] == "y")
      it->y = col;
    else if (coords[c] == "likelihood")
      it->likelihood = col;
    else
      throw InputError(
          path, "coords column " + std::to_string(c) + ": unknown coordinate '" + coords[c] + "'");
  }
  if (parts.empty()) {
    throw InputError(path, individuals ? "no columns for individual '" + individual + "'"
                                       : "no body part columns");
  }
  std::vector<std::string> names;
  for (const auto& p : parts) {
    if (p.x < 0 || p.y < 0)
      throw InputError(path, "body part '" + p.name + "' lacks an x or a y column");
    names.push_back(p.name);
  }
  const ResolvedMapping resolved =
      ResolveMapping(mapping, names, path, options.min_confidence.value_or(0.6f));
  // An explicit option wins over the mapping file.
  ResolvedMapping use = resolved;
  if (options.min_confidence) use.min_confidence = *options.min_confidence;

  SkeletonSequence sequence = NewSequence(mapping, path);
  int64_t ordinal = 0;
  auto add_row = [&](const std::vector<std::string>& cells, int at_line) {
    const std::string where = path + ": line " + std::to_string(at_line);
    if (cells.size() == 1 && cells[0].empty()) return;  // a blank line
    if (cells.size() != width) {
      throw InputError(where, "has " + std::to_string(cells.size()) + " columns, the header has " +
                                  std::to_string(width));
    }
    const auto index = leading == 1 ? ParseInteger(cells[0]) : std::nullopt;
    const int64_t frame = CheckedFrame(where, "frame index", index.value_or(ordinal));
    ++ordinal;
    std::vector<Keypoint> keypoints(parts.size());
    for (size_t k = 0; k < parts.size(); ++k) {
      const DlcPart& p = parts[k];
      const std::string at =
          where + " (frame " + std::to_string(frame) + ") body part '" + p.name + "'";
      const auto x = ParseCell(cells[p.x], at);
      const auto y = ParseCell(cells[p.y], at);
      const auto l =
          p.likelihood >= 0 ? ParseCell(cells[p.likelihood], at) : std::optional<float>(1.0f);
      if (x && y && l) keypoints[k] = {*x, *y, *l, true};
    }
    if (!sequence.frames.empty() && frame <= sequence.frames.back().frame) {
      throw InputError(where, "frame index " + std::to_string(frame) + " does not increase");
    }
    sequence.frames.push_back(MapKeypoints(use, keypoints, frame));
  };
  if (!first_data.empty()) add_row(first_data, line_number);
  while (std::getline(in, line)) add_row(SplitCsvLine(line), ++line_number);
  if (sequence.frames.empty()) throw InputError(path, "no frames after the header");
  return sequence;
}

namespace {
SkeletonSequence ImportOpenPoseJsonUnchecked(const std::string& path, const JointMapping& mapping,
                                             const SkeletonImportOptions& options) {
  std::vector<std::string> files;
  std::error_code ec;
  if (fs::is_directory(path, ec)) {
    for (const auto& entry : fs::directory_iterator(path)) {
      if (entry.is_regular_file() && entry.path().extension() == ".json")
        files.push_back(entry.path().string());
    }
    std::sort(files.begin(), files.end());
    if (files.empty()) throw InputError(path, "no OpenPose .json files in this folder");
  } else if (fs::is_regular_file(path, ec)) {
    files.push_back(path);
  } else {
    throw InputError(path, "no such file or folder");
  }
  static const std::vector<std::string> kCoco18 = {
      "Nose",  "Neck",   "RShoulder", "RElbow", "RWrist", "LShoulder", "LElbow", "LWrist", "RHip",
      "RKnee", "RAnkle", "LHip",      "LKnee",  "LAnkle", "REye",      "LEye",   "REar",   "LEar"};
  static const std::regex kNumbered(R"((\d+)_keypoints$)");
  SkeletonSequence sequence = NewSequence(mapping, path);
  std::optional<ResolvedMapping> resolved;
  int layout = -1;
  int64_t ordinal = 0;
  for (const auto& file : files) {
    const nlohmann::json json = ReadJsonFile(file);
    const std::string stem = fs::path(file).stem().string();
    std::smatch match;
    int64_t frame = ordinal;
    if (std::regex_search(stem, match, kNumbered))
      frame = ParseInteger(match[1].str()).value_or(ordinal);
    ++ordinal;
    if (!sequence.frames.empty() && frame <= sequence.frames.back().frame)
      frame = sequence.frames.back().frame + 1;
    const auto people = json.find("people");
    if (!json.is_object() || people == json.end() || !people->is_array()) {
      throw InputError(file, "not an OpenPose keypoint file: no 'people' array");
    }
    if (static_cast<int>(people->size()) <= options.person) {
      sequence.frames.push_back(EmptySkeletonFrame(mapping.skeleton, frame));
      continue;
    }
    const auto& person = (*people)[options.person];
    const auto pose = person.find("pose_keypoints_2d");
    if (pose == person.end() || !pose->is_array() || pose->size() % 3 != 0 || pose->empty()) {
      throw InputError(file, "people[" + std::to_string(options.person) +
                                 "].pose_keypoints_2d must be [x, y, c] * N");
    }
    const int n = static_cast<int>(pose->size() / 3);
    if (layout < 0) {
      layout = n;
      std::vector<std::string> names;
      if (n == 25) {
        names = Body25KeypointNames();
      } else if (n == 18) {
        names = kCoco18;
      } else {
        for (int i = 0; i < n; ++i) names.push_back(std::to_string(i));
      }
      resolved = ResolveMapping(mapping, names, file + " (" + std::to_string(n) + " keypoints)",
                                options.min_confidence.value_or(0.2f));
      if (options.min_confidence) resolved->min_confidence = *options.min_confidence;
    } else if (n != layout) {
      throw InputError(file, "has " + std::to_string(n) + " keypoints, earlier files have " +
                                 std::to_string(layout));
    }
    std::vector<Keypoint> keypoints(n);
    for (int i = 0; i < n; ++i) {
      const auto& x = (*pose)[3 * i];
      const auto& y = (*pose)[3 * i + 1];
      const auto& c = (*pose)[3 * i + 2];
      if (!x.is_number() || !y.is_number() || !c.is_number()) {
        throw InputError(file, "keypoint " + std::to_string(i) + " is not numeric");
      }
      const float conf = c.get<float>();
      if (conf > 0)
        keypoints[i] = {x.get<float>(), y.get<float>(), conf, true};  // c = 0: not detected
    }
    sequence.frames.push_back(MapKeypoints(*resolved, keypoints, frame));
  }
  if (layout < 0)
    Log("animate.skeleton")->warn("{}: no file holds person {}", path, options.person);
  return sequence;
}
}  // namespace

SkeletonSequence ImportOpenPoseJson(const std::string& path, const JointMapping& mapping,
                                    const SkeletonImportOptions& options) {
  RefuseBadOptions(options);
  // A field of the wrong JSON type (an array where a name belongs) is the file's fault.
  try {
    return ImportOpenPoseJsonUnchecked(path, mapping, options);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(path, std::string("wrong field: ") + e.what());
  }
}

namespace {
SkeletonSequence ImportCocoKeypointsUnchecked(const std::string& path, const JointMapping& mapping,
                                              const SkeletonImportOptions& options) {
  const nlohmann::json json = ReadJsonFile(path);
  const auto annotations = json.find("annotations");
  if (!json.is_object() || annotations == json.end() || !annotations->is_array()) {
    throw InputError(path, "not a COCO keypoint file: no 'annotations' array");
  }
  std::vector<std::string> names = Coco17KeypointNames();
  int category = options.category_id;
  if (const auto cats = json.find("categories"); cats != json.end() && cats->is_array()) {
    for (const auto& c : *cats) {
      if (!c.contains("keypoints") || !c.contains("id")) continue;
      if (category >= 0 && c["id"] != category) continue;
      category = c["id"].get<int>();
      names = c["keypoints"].get<std::vector<std::string>>();
      break;
    }
  }
  ResolvedMapping resolved =
      ResolveMapping(mapping, names, path, options.min_confidence.value_or(0.5f));
  if (options.min_confidence) resolved.min_confidence = *options.min_confidence;

  // Per image the annotation with the most labelled keypoints.
  std::map<int64_t, std::pair<int, const nlohmann::json*>> best;
  for (size_t a = 0; a < annotations->size(); ++a) {
    const auto& ann = (*annotations)[a];
    const std::string where = path + ": annotations[" + std::to_string(a) + "]";
    if (!ann.contains("image_id") || !ann["image_id"].is_number_integer())
      throw InputError(where, "no image_id");
    if (category >= 0 && ann.contains("category_id") && ann["category_id"] != category) continue;
    const auto kp = ann.find("keypoints");
    if (kp == ann.end() || !kp->is_array() || kp->size() != 3 * names.size()) {
      throw InputError(where, "keypoints must be [x, y, v] * " + std::to_string(names.size()) +
                                  ", got " + std::to_string(kp == ann.end() ? 0 : kp->size()) +
                                  " numbers");
    }
    int labelled = 0;
    for (size_t i = 2; i < kp->size(); i += 3) labelled += (*kp)[i].get<double>() > 0 ? 1 : 0;
    const int64_t image = FrameFromJson(where, "image_id", ann["image_id"]);
    auto it = best.find(image);
    if (it == best.end() || labelled > it->second.first) best[image] = {labelled, &ann};
  }
  std::vector<int64_t> images;
  if (const auto imgs = json.find("images"); imgs != json.end() && imgs->is_array()) {
    for (size_t i = 0; i < imgs->size(); ++i) {
      const auto& img = (*imgs)[i];
      if (!img.contains("id") || !img["id"].is_number_integer()) continue;
      images.push_back(
          FrameFromJson(path + ": images[" + std::to_string(i) + "]", "id", img["id"]));
    }
  }
  for (const auto& [image, unused] : best) images.push_back(image);
  std::sort(images.begin(), images.end());
  images.erase(std::unique(images.begin(), images.end()), images.end());
  if (images.empty()) throw InputError(path, "no images and no annotations");

  SkeletonSequence sequence = NewSequence(mapping, path);
  for (int64_t image : images) {
    const auto it = best.find(image);
    if (it == best.end()) {
      sequence.frames.push_back(EmptySkeletonFrame(mapping.skeleton, image));
      continue;
    }
    const auto& kp = (*it->second.second)["keypoints"];
    std::vector<Keypoint> keypoints(names.size());
    for (size_t i = 0; i < names.size(); ++i) {
      const double v = kp[3 * i + 2].get<double>();
      // v: 0 not labelled, 1 labelled but hidden, 2 labelled and visible.
      if (v > 0)
        keypoints[i] = {kp[3 * i].get<float>(), kp[3 * i + 1].get<float>(), v >= 2 ? 1.0f : 0.5f,
                        true};
    }
    sequence.frames.push_back(MapKeypoints(resolved, keypoints, image));
  }
  return sequence;
}
}  // namespace

SkeletonSequence ImportCocoKeypoints(const std::string& path, const JointMapping& mapping,
                                     const SkeletonImportOptions& options) {
  RefuseBadOptions(options);
  // A field of the wrong JSON type (an array where a name belongs) is the file's fault.
  try {
    return ImportCocoKeypointsUnchecked(path, mapping, options);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(path, std::string("wrong field: ") + e.what());
  }
}

}  // namespace ss

namespace ss {

JointMapping IdentityMapping(const SkeletonDef& def) {
  JointMapping m;
  m.context = "identity mapping onto " + def.name;
  m.skeleton = def;
  for (const auto& name : def.joints) m.sources.push_back({SourceKeypoint{name, -1}});
  return m;
}

namespace {
SkeletonSequence ImportSynthTruthUnchecked(const std::string& path, const std::string& camera,
                                           const JointMapping& mapping,
                                           const SkeletonImportOptions& options) {
  // Find the truth folder and the CSV.
  fs::path truth_dir, csv;
  if (fs::is_regular_file(path)) {
    csv = path;
    truth_dir = fs::path(path).parent_path().parent_path();
  } else if (fs::exists(fs::path(path) / "truth" / "truth.json")) {
    truth_dir = fs::path(path) / "truth";
  } else if (fs::exists(fs::path(path) / "truth.json")) {
    truth_dir = path;
  } else {
    throw InputError(
        path, "not a synthetic session, its truth folder or a <camera>/joints.csv (no truth.json)");
  }
  nlohmann::json truth;
  if (fs::exists(truth_dir / "truth.json"))
    truth = ReadJsonFile((truth_dir / "truth.json").string());
  std::string cam = camera;
  if (csv.empty()) {
    if (cam.empty()) {
      if (!truth.contains("cameras") || !truth["cameras"].is_array() || truth["cameras"].empty()) {
        throw InputError((truth_dir / "truth.json").string(), "lists no cameras");
      }
      cam = truth["cameras"][0].value("name", std::string());
    }
    csv = truth_dir / cam / "joints.csv";
  } else if (cam.empty()) {
    cam = csv.parent_path().filename().string();
  }
  RefuseOversizedFile(csv.string());
  std::ifstream in(csv);
  if (!in) throw InputError(csv.string(), "cannot open (a figure session's projected joint truth)");
  std::string line;
  if (!std::getline(in, line)) throw InputError(csv.string(), "empty file");
  const auto header = SplitCsvLine(line);
  auto column = [&](const std::string& name) {
    const auto it = std::find(header.begin(), header.end(), name);
    if (it == header.end())
      throw InputError(csv.string(), "no '" + name + "' column in the header");
    return static_cast<size_t>(it - header.begin());
  };
  const size_t c_frame = column("frame"), c_subject = column("subject"), c_name = column("name"),
               c_x = column("x"), c_y = column("y");
  const size_t need = std::max({c_frame, c_subject, c_name, c_x, c_y}) + 1;

  // Rows of the chosen subject, grouped by frame, keypoints by name in first-seen order.
  std::vector<std::string> names;
  std::map<std::string, int> index_of;
  std::map<int64_t, std::map<int, Keypoint>> frames;
  int line_number = 1;
  while (std::getline(in, line)) {
    ++line_number;
    if (line.empty() || line == "\r") continue;
    const auto cells = SplitCsvLine(line);
    const std::string where = csv.string() + ":" + std::to_string(line_number);
    if (cells.size() < need) throw InputError(where, "too few cells");
    const auto frame = ParseInteger(cells[c_frame]);
    const auto subject = ParseInteger(cells[c_subject]);
    if (!frame || !subject) throw InputError(where, "frame and subject must be integers");
    CheckedFrame(where, "frame", *frame);
    if (*subject != options.person) continue;
    auto [it, added] = index_of.emplace(cells[c_name], static_cast<int>(names.size()));
    if (added) names.push_back(cells[c_name]);
    const auto x = ParseCell(cells[c_x], where), y = ParseCell(cells[c_y], where);
    Keypoint k;
    if (x && y) k = {*x, *y, 1.0f, true};
    frames[*frame][it->second] = k;
  }
  if (frames.empty()) {
    throw InputError(csv.string(), "no rows for subject " + std::to_string(options.person));
  }
  ResolvedMapping resolved =
      ResolveMapping(mapping, names, csv.string(), options.min_confidence.value_or(0.0f));
  if (options.min_confidence) resolved.min_confidence = *options.min_confidence;

  SkeletonSequence sequence;
  sequence.skeleton = mapping.skeleton;
  std::string session = truth_dir.parent_path().filename().string();
  const fs::path session_json = truth_dir.parent_path() / "session.json";
  if (fs::exists(session_json))
    session = ReadJsonFile(session_json.string()).value("name", session);
  sequence.clip = session + "/" + cam;
  sequence.fps = truth.is_object() ? truth.value("fps", 0.0) : 0.0;
  for (const auto& [frame, by_index] : frames) {
    std::vector<Keypoint> keypoints(names.size());
    for (const auto& [k, v] : by_index) keypoints[k] = v;
    sequence.frames.push_back(MapKeypoints(resolved, keypoints, frame));
  }
  return sequence;
}
}  // namespace

SkeletonSequence ImportSynthTruth(const std::string& path, const std::string& camera,
                                  const JointMapping& mapping,
                                  const SkeletonImportOptions& options) {
  RefuseBadOptions(options);
  // A field of the wrong JSON type (an array where a name belongs) is the file's fault.
  try {
    return ImportSynthTruthUnchecked(path, camera, mapping, options);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(path, std::string("wrong field: ") + e.what());
  }
}

}  // namespace ss
