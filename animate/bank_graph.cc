#include "animate/bank_graph.h"

#include <algorithm>
#include <unordered_map>

#include "core/bank.h"
#include "core/error.h"
#include "core/log.h"

namespace ss {

int BankGraph::FrameOf(int bank, int64_t sprite_id) const {
  for (size_t i = 0; i < frames.size(); ++i) {
    if (frames[i].bank == bank && frames[i].sprite_id == sprite_id) return static_cast<int>(i);
  }
  return -1;
}

BankGraph LoadBankGraph(const std::vector<std::string>& bank_paths,
                        const std::vector<std::string>& tags, const std::atomic<bool>* cancel) {
  auto stop_if_cancelled = [cancel](const std::string& bank) {
    if (cancel != nullptr && cancel->load()) throw WorkError(bank, "cancelled");
  };
  BankGraph out;
  out.bank_paths = bank_paths;
  std::vector<FrameInfo> infos;
  std::vector<TransitionEdge> edges;
  int clip = 0;
  for (size_t b = 0; b < bank_paths.size(); ++b) {
    const Bank bank(bank_paths[b]);
    // One snapshot for the sprites, tags and transitions of a bank that may still be written.
    const BankSnapshot snapshot(bank);
    stop_if_cancelled(bank_paths[b]);
    const std::vector<SpriteFeatures> features = bank.LoadFeatures();
    stop_if_cancelled(bank_paths[b]);
    if (features.empty())
      throw InputError(bank_paths[b], "the bank holds no sprites in complete clips");
    // The source frame interval: the median timestamp step between clip neighbours.
    std::vector<int64_t> steps;
    for (const SpriteFeatures& f : features) {
      if (f.next >= 0) {
        const SpriteFeatures& n = features[f.next];
        const int64_t frames = std::max<int64_t>(1, n.frame - f.frame);
        if (n.timestamp_ns > f.timestamp_ns)
          steps.push_back((n.timestamp_ns - f.timestamp_ns) / frames);
      }
    }
    double interval_s = 1.0 / 30.0;
    if (!steps.empty()) {
      std::nth_element(steps.begin(), steps.begin() + steps.size() / 2, steps.end());
      interval_s = static_cast<double>(steps[steps.size() / 2]) * 1e-9;
    }
    out.frame_interval_s.push_back(interval_s);

    const int base = static_cast<int>(infos.size());
    std::unordered_map<int64_t, int> index_of;
    for (size_t i = 0; i < features.size(); ++i) {
      const SpriteFeatures& f = features[i];
      // A new graph clip wherever the bank's run of consecutive frames breaks.
      if (i == 0 || features[i - 1].next != static_cast<int32_t>(i)) ++clip;
      FrameInfo info;
      info.clip = clip;
      info.velocity_m = Eigen::Vector2d(f.velocity_x_m_s, f.velocity_y_m_s) * interval_s;
      if (f.floor) info.heading_rad = f.heading_rad;
      if (f.mirrored) info.tags.push_back("mirrored");
      index_of[f.id] = base + static_cast<int>(i);
      infos.push_back(std::move(info));
      out.frames.push_back({static_cast<int>(b), f.id});
    }
    for (const std::string& tag : tags) {
      if (tag == "mirrored") continue;
      for (int64_t id : bank.SpritesTagged(tag)) {
        const auto it = index_of.find(id);
        if (it != index_of.end()) infos[it->second].tags.push_back(tag);
      }
    }
    int64_t kept = 0;
    stop_if_cancelled(bank_paths[b]);
    const std::vector<TransitionRecord> transitions = bank.LoadTransitions();
    stop_if_cancelled(bank_paths[b]);
    for (const TransitionRecord& t : transitions) {
      const auto from = index_of.find(t.from_sprite);
      const auto to = index_of.find(t.to_sprite);
      if (from == index_of.end() || to == index_of.end()) continue;  // an incomplete clip's
      edges.push_back({from->second, to->second, std::max(0.0, t.cost)});
      ++kept;
    }
    Log("animate.bank")
        ->info("{}: {} frames, {} transitions, source interval {:.4f} s", bank_paths[b],
               features.size(), kept, interval_s);
  }
  out.graph = TransitionGraph(std::move(infos), edges);
  return out;
}

}  // namespace ss
