#include "pipeline/track/tracker.h"

#include <algorithm>
#include <limits>
#include <tuple>

namespace ss {

std::vector<int> Tracker::Update(int64_t timestamp_ns, const std::vector<TrackInput>& inputs) {
  std::erase_if(subjects_, [&](const Subject& s) {
    return timestamp_ns - s.last_seen_ns > options_.forget_after_ns;
  });

  // Every admissible (distance, input, subject) pair, matched greedily by distance.
  std::vector<std::tuple<double, size_t, size_t>> pairs;
  for (size_t i = 0; i < inputs.size(); ++i) {
    for (size_t k = 0; k < subjects_.size(); ++k) {
      const Subject& s = subjects_[k];
      const double dt = std::max<int64_t>(timestamp_ns - s.last_seen_ns, 0) * 1e-9;
      const double d = (inputs[i].point_in_ground - s.point).norm();
      const double ratio = std::max(inputs[i].area, 1.0) / std::max(s.area, 1.0);
      if (d <= options_.max_speed_m_per_s * dt + options_.reach_slack_m &&
          ratio <= options_.max_area_ratio && ratio >= 1.0 / options_.max_area_ratio) {
        pairs.emplace_back(d, i, k);
      }
    }
  }
  std::sort(pairs.begin(), pairs.end());
  std::vector<int> ids(inputs.size(), -1);
  std::vector<bool> taken(subjects_.size(), false);
  for (const auto& [d, i, k] : pairs) {
    if (ids[i] != -1 || taken[k]) continue;
    ids[i] = subjects_[k].id;
    taken[k] = true;
    subjects_[k].point = inputs[i].point_in_ground;
    subjects_[k].area = inputs[i].area;
    subjects_[k].last_seen_ns = timestamp_ns;
  }
  for (size_t i = 0; i < inputs.size(); ++i) {
    if (ids[i] != -1) continue;
    ids[i] = next_id_++;
    subjects_.push_back({ids[i], inputs[i].point_in_ground, inputs[i].area, timestamp_ns});
  }
  return ids;
}

std::vector<ClipCutter::Event> ClipCutter::Update(const std::vector<int>& subjects,
                                                  const std::vector<bool>& usable) {
  std::vector<Event> events;
  std::vector<Open> still_open;
  // Clips of subjects not seen in this frame end here.
  for (const Open& o : open_) {
    if (std::find(subjects.begin(), subjects.end(), o.subject) == subjects.end()) {
      events.push_back({o.subject, -1, true, o.clip});
    }
  }
  for (size_t i = 0; i < subjects.size(); ++i) {
    const auto it = std::find_if(open_.begin(), open_.end(),
                                 [&](const Open& o) { return o.subject == subjects[i]; });
    const bool was_open = it != open_.end();
    if (usable[i]) {
      const int64_t clip = was_open ? it->clip : next_clip_++;
      events.push_back({subjects[i], clip, false});
      still_open.push_back({subjects[i], clip});
    } else {
      events.push_back({subjects[i], -1, was_open, was_open ? it->clip : -1});
    }
  }
  open_ = std::move(still_open);
  return events;
}

std::vector<int64_t> ClipCutter::CloseAll() {
  std::vector<int64_t> closed;
  for (const Open& o : open_) closed.push_back(o.clip);
  open_.clear();
  return closed;
}

}  // namespace ss
