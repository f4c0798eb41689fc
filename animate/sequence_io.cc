#include "animate/sequence_io.h"

#include <fstream>

#include "core/error.h"
#include "core/replace_file.h"

namespace ss {
namespace {

using nlohmann::json;

json SpritesToJson(const std::vector<SpriteSequence>& sprites) {
  json out = json::array();
  for (const SpriteSequence& s : sprites) {
    json steps = json::array();
    for (size_t t = 0; t < s.frames.size(); ++t) {
      json step = {s.frames[t].bank, s.frames[t].sprite_id, s.positions_m[t].x(),
                   s.positions_m[t].y()};
      if (!s.turns_rad.empty()) step.push_back(s.TurnAt(t));
      steps.push_back(std::move(step));
    }
    out.push_back({{"name", s.name}, {"steps", std::move(steps)}});
  }
  return out;
}

std::vector<SpriteSequence> SpritesFromJson(const json& j, const std::string& path,
                                            const std::string& field, int num_banks) {
  if (!j.is_array()) throw InputError(path, field + ": expected a list");
  std::vector<SpriteSequence> out;
  for (size_t i = 0; i < j.size(); ++i) {
    const std::string f = field + "[" + std::to_string(i) + "]";
    const json& s = j[i];
    if (!s.is_object() || !s.contains("steps") || !s["steps"].is_array()) {
      throw InputError(
          path, f + ".steps: expected a list of [bank, sprite, x_m, y_m] (or with turn_rad)");
    }
    SpriteSequence seq;
    seq.name = s.value("name", "sprite" + std::to_string(i));
    for (size_t t = 0; t < s["steps"].size(); ++t) {
      const json& step = s["steps"][t];
      if (!step.is_array() || step.size() < 4 || step.size() > 5 || !step[0].is_number_integer() ||
          !step[1].is_number_integer() || !step[2].is_number() || !step[3].is_number() ||
          (step.size() == 5 && !step[4].is_number())) {
        throw InputError(path, f + ".steps[" + std::to_string(t) +
                                   "]: expected [bank, sprite, x_m, y_m] or [bank, sprite, x_m, "
                                   "y_m, turn_rad]");
      }
      const int bank = step[0].get<int>();
      if (bank < 0 || bank >= num_banks) {
        throw InputError(
            path, f + ".steps[" + std::to_string(t) + "][0]: no bank " + std::to_string(bank));
      }
      seq.frames.push_back({bank, step[1].get<int64_t>()});
      seq.positions_m.emplace_back(step[2].get<double>(), step[3].get<double>());
      if (step.size() == 5) {
        seq.turns_rad.resize(t, 0.0);  // the steps before without a turn
        seq.turns_rad.push_back(step[4].get<double>());
      }
    }
    if (!seq.turns_rad.empty()) seq.turns_rad.resize(seq.frames.size(), 0.0);
    if (seq.frames.empty()) throw InputError(path, f + ".steps: empty");
    out.push_back(std::move(seq));
  }
  return out;
}

}  // namespace

std::vector<SpriteSequence> ToSpriteSequences(const BankGraph& bank,
                                              const std::vector<std::string>& names,
                                              const std::vector<Track>& tracks) {
  std::vector<SpriteSequence> out;
  for (size_t s = 0; s < tracks.size(); ++s) {
    SpriteSequence seq;
    seq.name = s < names.size() ? names[s] : "sprite" + std::to_string(s);
    for (int t = 0; t < tracks[s].size(); ++t) {
      seq.frames.push_back(bank.frames[tracks[s].frames[t]]);
      seq.positions_m.push_back(tracks[s].positions_m[t]);
    }
    seq.turns_rad = tracks[s].turns_rad;
    out.push_back(std::move(seq));
  }
  return out;
}

int LongestSequence(const std::vector<SpriteSequence>& sprites) {
  int n = 0;
  for (const SpriteSequence& s : sprites) n = std::max(n, static_cast<int>(s.frames.size()));
  return n;
}

void WriteSequenceFile(const std::string& path, const SequenceFile& file) {
  json j = {{"format", "spritestation-sequences"},
            {"version", kSequenceFormatVersion},
            {"frame_rate", file.frame_rate},
            {"num_steps", file.num_steps},
            {"camera", file.camera_path},
            {"background", file.background_path},
            {"banks", file.bank_paths},
            {"sprites", SpritesToJson(file.sprites)}};
  json stages = json::array();
  for (const SequenceStage& stage : file.stages) {
    stages.push_back({{"seconds", stage.seconds},
                      {"cost", stage.cost},
                      {"sprites", SpritesToJson(stage.sprites)}});
  }
  j["stages"] = std::move(stages);
  j["summary"] = file.summary.is_null() ? json::object() : file.summary;
  ReplaceFile(path, j.dump(1) + "\n", "the sequences");
}

namespace {

SequenceFile ReadSequenceJson(const json& j, const std::string& path) {
  if (!j.is_object() || j.value("format", "") != "spritestation-sequences") {
    throw InputError(path, "format: not a spritestation sequences file");
  }
  if (j.value("version", 0) != kSequenceFormatVersion) {
    throw InputError(path,
                     "version: this build reads version " + std::to_string(kSequenceFormatVersion));
  }
  SequenceFile file;
  try {
    file.frame_rate = j.at("frame_rate").get<double>();
    file.camera_path = j.at("camera").get<std::string>();
    file.background_path = j.value("background", "");
    file.bank_paths = j.at("banks").get<std::vector<std::string>>();
  } catch (const json::exception& e) {
    throw InputError(path, std::string("missing or wrong field: ") + e.what());
  }
  if (!(file.frame_rate > 0)) throw InputError(path, "frame_rate: must be > 0");
  const int banks = static_cast<int>(file.bank_paths.size());
  file.sprites = SpritesFromJson(j.value("sprites", json()), path, "sprites", banks);
  file.num_steps = LongestSequence(file.sprites);
  if (j.contains("stages") && j["stages"].is_array()) {
    for (size_t k = 0; k < j["stages"].size(); ++k) {
      const json& s = j["stages"][k];
      SequenceStage stage;
      stage.seconds = s.value("seconds", 0.0);
      stage.cost = s.value("cost", 0.0);
      stage.sprites = SpritesFromJson(s.value("sprites", json()), path,
                                      "stages[" + std::to_string(k) + "].sprites", banks);
      file.stages.push_back(std::move(stage));
    }
  }
  file.summary = j.value("summary", json::object());
  return file;
}

}  // namespace

SequenceFile ReadSequenceFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path, "cannot read the sequences");
  json j;
  try {
    j = json::parse(in);
  } catch (const json::exception& e) {
    throw InputError(path, std::string("not valid JSON: ") + e.what());
  }
  // Any field of the wrong JSON type (an array where text belongs) is the file's fault.
  try {
    return ReadSequenceJson(j, path);
  } catch (const json::exception& e) {
    throw InputError(path, std::string("wrong field: ") + e.what());
  }
}

}  // namespace ss
