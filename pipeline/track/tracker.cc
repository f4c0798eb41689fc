#include "pipeline/track/tracker.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <string>
#include <tuple>

#include "core/error.h"
#include "core/log.h"
#include "core/option_checks.h"

namespace ss {

bool TrackerOptions::IsValid(std::string* why) const {
  OptionProblems check(why);
  check.Within(max_speed_m_per_s, Positive(), "max_speed_m_per_s", "a positive number");
  check.Within(reach_slack_m, AtLeast(0), "reach_slack_m", "a number >= 0");
  check.Within(max_area_ratio, AtLeast(1), "max_area_ratio", "a ratio >= 1");
  check.Within(forget_after_ns, AtLeast(0), "forget_after_ns", "a duration >= 0");
  return check.ok();
}

Tracker::Tracker(TrackerOptions options) : options_(options) {
  if (std::string why; !options_.IsValid(&why)) throw InputError("tracker options", why);
}

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

namespace {

double AreaOf(const cv::Rect& r) { return static_cast<double>(r.width) * r.height; }

// The share of `inner`'s area inside `outer`.
double ShareInside(const cv::Rect& inner, const cv::Rect& outer) {
  const double a = AreaOf(inner);
  return a > 0 ? AreaOf(inner & outer) / a : 0.0;
}

}  // namespace

std::vector<bool> MergeDetector::Update(const std::vector<Blob>& blobs) {
  constexpr int kMaxSubjects = 8;
  // What each blob got from the tracks of the frame before.
  struct Share {
    int subjects;
    int frames;  // the giving track's frames in a row (counted on in this blob)
    double merged_area;
    bool swallowed;            // a lost track, not the blob's own
    int from;                  // the giving track
    std::vector<int> members;  // the tracks swallowed into the giving blob, counted in it
  };
  // Looked up once: Log() takes two global locks, and this runs every frame of every camera.
  static const std::shared_ptr<spdlog::logger> log = Log("pipeline.track");
  const bool debug = log->should_log(spdlog::level::debug);
  ++updates_;
  std::vector<std::vector<Share>> shares(blobs.size());
  // Blobs whose track was not seen in the frame before: new subjects, or ones found again.
  std::vector<bool> fresh(blobs.size(), true);
  for (size_t i = 0; i < blobs.size(); ++i) {
    for (const Seen& p : previous_) fresh[i] = fresh[i] && p.track != blobs[i].track;
  }
  // A fresh blob came out of one track of the frame before at most: of those whose box holds it,
  // the one with the smallest box. A blob of several subjects can have a box that holds another
  // track's box whole; a piece in both is that track's, not one subject of each.
  std::vector<const Seen*> parent(blobs.size(), nullptr);
  for (size_t i = 0; i < blobs.size(); ++i) {
    if (!fresh[i]) continue;
    for (const Seen& p : previous_) {
      if (ShareInside(blobs[i].box, p.box) >= options_.split_share &&
          (parent[i] == nullptr || AreaOf(p.box) < AreaOf(parent[i]->box))) {
        parent[i] = &p;
      }
    }
  }
  for (const Seen& p : previous_) {
    // This frame's blobs that came out of p: its own (the tracker's) and new ones in its box.
    std::vector<size_t> children;
    for (size_t i = 0; i < blobs.size(); ++i) {
      if (blobs[i].track == p.track || parent[i] == &p) {
        children.push_back(i);
      }
    }
    if (children.size() >= 2) {  // a split: one subject each, unless a piece kept most of it
      // Pieces that are tracks swallowed into p, come out again under their own ids: partners
      // that left. The piece keeping most of p's area keeps its count less theirs.
      std::vector<int> left;
      for (size_t i : children) {
        if (std::find(p.members.begin(), p.members.end(), blobs[i].track) != p.members.end())
          left.push_back(blobs[i].track);
      }
      for (size_t i : children) {
        const bool keeps = p.subjects >= 2 && blobs[i].area >= options_.keep_area_share * p.area;
        // The pieces of a merged blob are subjects: they may merge again at once.
        const int frames = p.subjects >= 2 ? std::max(p.frames, options_.min_track_frames) : 1;
        std::vector<int> members;
        if (keeps) {
          std::copy_if(p.members.begin(), p.members.end(), std::back_inserter(members),
                       [&](int t) { return std::find(left.begin(), left.end(), t) == left.end(); });
        }
        const int count = keeps ? std::max(p.subjects - static_cast<int>(left.size()), 1) : 1;
        shares[i].push_back(
            {count, frames, count >= 2 ? p.merged_area : 0, false, p.track, std::move(members)});
        if (debug) {
          log->debug(
              "merge update {}: track {} ({} subjects, area {:.0f}) split: track {} area {:.0f}{}",
              updates_, p.track, p.subjects, p.area, blobs[i].track, blobs[i].area,
              keeps ? " keeps its count" : "");
        }
      }
      continue;
    }
    if (children.size() == 1) {
      shares[children.front()].push_back(
          {p.subjects, p.frames + 1, p.merged_area, false, p.track, p.members});
      continue;
    }
    // No blob of its own: swallowed by the blob whose box holds most of its box, if any does.
    size_t best = blobs.size();
    double best_share = options_.absorb_share;
    for (size_t i = 0; i < blobs.size(); ++i) {
      const double share = ShareInside(p.box, blobs[i].box);
      if (share >= best_share) {
        best = i;
        best_share = share;
      }
    }
    if (best < blobs.size())
      shares[best].push_back({p.subjects, p.frames + 1, p.merged_area, true, p.track, p.members});
  }
  std::vector<bool> merged(blobs.size(), false);
  std::vector<Seen> seen;
  seen.reserve(blobs.size());
  for (size_t i = 0; i < blobs.size(); ++i) {
    // A lost track swallowed by a blob that has its own track (or other tracks) counts when it
    // had been seen long enough; a blob made only of one lost track is its continuation.
    int n = 0, frames = 1;
    double at_merge = 0;
    std::vector<int> members;
    const bool several = shares[i].size() >= 2;
    std::string from;  // for the debug log
    for (const Share& sh : shares[i]) {
      if (debug) {
        from += fmt::format(" {}{}:{}x{}f", sh.swallowed ? "swallowed " : "", sh.from, sh.subjects,
                            sh.frames);
      }
      if (several && sh.swallowed && sh.frames - 1 < options_.min_track_frames) continue;
      n += sh.subjects;
      frames = std::max(frames, sh.frames);
      at_merge = std::max(at_merge, sh.merged_area);
      members.insert(members.end(), sh.members.begin(), sh.members.end());
      if (several && sh.swallowed) members.push_back(sh.from);
    }
    n = std::clamp(n, 1, kMaxSubjects);
    if (n >= 2 && at_merge <= 0) at_merge = blobs[i].area;  // it merged in this frame
    const bool dropped = n >= 2 && blobs[i].area < options_.drop_area_share * at_merge;
    if (dropped) n = 1;
    if (debug && (several || n >= 2 || dropped)) {
      const cv::Rect& b = blobs[i].box;
      log->debug("merge update {}: track {} box {}x{}+{}+{} area {:.0f} counts {}{} from{}",
                 updates_, blobs[i].track, b.width, b.height, b.x, b.y, blobs[i].area, n,
                 dropped ? " (area under drop_area_share of the merge's)" : "", from);
    }
    if (n < 2) {
      at_merge = 0;
      members.clear();
    }
    merged[i] = n >= 2;
    if (blobs[i].track >= 0) {
      seen.push_back({blobs[i].track, blobs[i].box, n, at_merge, std::min(frames, 1000),
                      blobs[i].area, std::move(members)});
    }
  }
  previous_ = std::move(seen);
  return merged;
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
