#pragma once
// The optimizer's output (docs/animation.md "Sequences"): a versioned JSON file with, per
// sprite, the bank sprite shown and the ground position at every step, the virtual camera,
// background and banks to render them with, optional intermediate stages of the run, and
// the run's summary. `render` reads only this file (and the banks it names).
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "animate/bank_graph.h"
#include "animate/track.h"

namespace ss {

inline constexpr int kSequenceFormatVersion = 1;

struct SpriteSequence {
  std::string name;
  std::vector<BankFrameRef> frames;          // per step
  std::vector<Eigen::Vector2d> positions_m;  // ground contact point per step
  // Floor sprites: how far each step is turned from its source frame's heading, radians (empty:
  // none turned).
  std::vector<double> turns_rad;
  double TurnAt(size_t t) const { return t < turns_rad.size() ? turns_rad[t] : 0.0; }
};

// The sequences at one moment of the optimization.
struct SequenceStage {
  double seconds = 0.0;
  double cost = 0.0;
  std::vector<SpriteSequence> sprites;
};

struct SequenceFile {
  double frame_rate = 30.0;
  int num_steps = 0;  // the longest sequence; shorter sprites hold their last state
  std::string camera_path;
  std::string background_path;  // "" = none
  std::vector<std::string> bank_paths;
  std::vector<SpriteSequence> sprites;
  std::vector<SequenceStage> stages;  // optional: intermediate results, in time order
  nlohmann::json summary;             // the optimizer's report (free form)
};

// Tracks (graph frames) as bank sprites and positions.
std::vector<SpriteSequence> ToSpriteSequences(const BankGraph& bank,
                                              const std::vector<std::string>& names,
                                              const std::vector<Track>& tracks);
// Steps of the longest sequence.
int LongestSequence(const std::vector<SpriteSequence>& sprites);

void WriteSequenceFile(const std::string& path, const SequenceFile& file);  // WorkError
SequenceFile ReadSequenceFile(const std::string& path);  // InputError naming the file and field

}  // namespace ss
