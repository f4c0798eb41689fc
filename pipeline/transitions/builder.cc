#include "pipeline/transitions/builder.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <mutex>
#include <thread>
#include <tuple>

#include "core/elapsed.h"
#include "core/error.h"
#include "core/log.h"
#include "core/option_checks.h"

namespace ss {

void KeepCheapestPerSprite(std::vector<Transition>* transitions, int keep) {
  if (keep <= 0) return;
  const auto cheaper = [](const Transition& a, const Transition& b) {
    return std::tie(a.cost, a.to) < std::tie(b.cost, b.to);
  };
  const auto by_to = [](const Transition& a, const Transition& b) { return a.to < b.to; };
  auto& t = *transitions;
  size_t write = 0;
  for (size_t begin = 0; begin < t.size();) {
    size_t end = begin + 1;
    while (end < t.size() && t[end].from == t[begin].from) ++end;
    const auto first = t.begin() + static_cast<std::ptrdiff_t>(begin);
    auto last = t.begin() + static_cast<std::ptrdiff_t>(end);
    if (end - begin > static_cast<size_t>(keep)) {
      std::nth_element(first, first + keep, last, cheaper);
      last = first + keep;
    }
    std::sort(first, last, by_to);
    for (auto it = first; it != last; ++it) t[write++] = *it;
    begin = end;
  }
  t.resize(write);
}

bool BuildOptions::IsValid(std::string* why) const {
  OptionProblems check(why);
  check.Within(threads, AtLeast(1), "threads", "at least 1 thread");
  return check.ok();
}

TransitionBuilder::TransitionBuilder(const TransitionWeights& weights, double px_per_m)
    : classifier_(weights), store_(weights.window, px_per_m), index_(classifier_) {}

const TransitionBuilder::Neighbour* TransitionBuilder::Find(const std::vector<Neighbour>& list,
                                                            int32_t index) {
  auto it = std::lower_bound(list.begin(), list.end(), index,
                             [](const Neighbour& n, int32_t i) { return n.index < i; });
  return it != list.end() && it->index == index ? &*it : nullptr;
}

bool TransitionBuilder::Compare(int32_t i, int32_t j, double* d) {
  if (classifier_.SignatureRejects(store_, i, j)) {
    ++stats_.signature_rejected;
    return false;
  }
  ++stats_.stage2_evaluations;
  return classifier_.Stage2(store_, i, j, d);
}

void TransitionBuilder::InsertNeighbour(int32_t at, int32_t index, double distance) {
  auto& list = neighbours_[at];
  auto it = std::lower_bound(list.begin(), list.end(), index,
                             [](const Neighbour& n, int32_t i) { return n.index < i; });
  list.insert(it, Neighbour{index, distance});
}

double TransitionBuilder::KeptDistance(int32_t i, int32_t j) const {
  const Neighbour* n = Find(neighbours_[i], j);
  return n ? n->distance : -1.0;
}

void TransitionBuilder::BuildFromScratch(std::span<const SpriteInput> sprites,
                                         const BuildOptions& options) {
  if (std::string why; !options.IsValid(&why)) throw InputError("build options", why);
  if (sprites.empty())
    throw InputError("sprites",
                     "the set is empty: there are no sprites to find transitions between");
  auto log = Log("pipeline.transitions");
  store_.Clear();
  neighbours_.clear();
  stats_ = BuildStats{};
  const int threads = options.threads;

  auto start = std::chrono::steady_clock::now();
  store_.Append(sprites, threads);
  stats_.seconds_images = SecondsSince(start);

  start = std::chrono::steady_clock::now();
  index_.Build(store_.all_cheap());
  stats_.seconds_index = SecondsSince(start);

  // Stage 1 through the index, stage 2 on the candidates j > i, in blocks over i.
  start = std::chrono::steady_clock::now();
  const int32_t n = store_.size();
  struct Found {
    int32_t i, j;
    double distance;
  };
  std::atomic<int32_t> cursor{0};
  std::atomic<int64_t> candidates{0}, evaluations{0};
  std::mutex merge_mutex;
  std::vector<Found> found;
  size_t done = 0;
  auto work = [&] {
    constexpr int32_t kBlock = 256;
    std::vector<int32_t> hits;
    std::vector<Found> local;
    int64_t local_candidates = 0, local_evaluations = 0;
    for (int32_t begin; (begin = cursor.fetch_add(kBlock)) < n;) {
      const int32_t end = std::min(n, begin + kBlock);
      for (int32_t i = begin; i < end; ++i) {
        hits.clear();
        index_.Query(store_.cheap(i), &hits);
        for (size_t h = 0; h < hits.size(); ++h) {
          if (h + 8 < hits.size()) store_.PrefetchCoarse(hits[h + 8]);
          const int32_t j = hits[h];
          if (j <= i) continue;
          ++local_candidates;
          if (classifier_.SignatureRejects(store_, i, j)) continue;
          ++local_evaluations;
          double d;
          if (classifier_.Stage2(store_, i, j, &d)) local.push_back({i, j, d});
        }
      }
      std::lock_guard<std::mutex> lock(merge_mutex);
      found.insert(found.end(), local.begin(), local.end());
      local.clear();
      done += end - begin;
      if (options.progress) options.progress(done, n);
    }
    candidates += local_candidates;
    evaluations += local_evaluations;
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(work);
  work();
  for (auto& t : pool) t.join();

  neighbours_.assign(n, {});
  std::vector<int32_t> degree(n, 0);
  for (const Found& f : found) {
    ++degree[f.i];
    ++degree[f.j];
  }
  for (int32_t i = 0; i < n; ++i) neighbours_[i].reserve(degree[i]);
  for (const Found& f : found) {
    neighbours_[f.i].push_back({f.j, f.distance});
    neighbours_[f.j].push_back({f.i, f.distance});
  }
  for (auto& list : neighbours_) {
    std::sort(list.begin(), list.end(),
              [](const Neighbour& a, const Neighbour& b) { return a.index < b.index; });
  }
  stats_.seconds_pairs = SecondsSince(start);
  stats_.sprites = n;
  stats_.clips = static_cast<int64_t>(store_.clip_count());
  stats_.stage1_candidates = candidates.load();
  stats_.stage2_evaluations = evaluations.load();
  stats_.signature_rejected = stats_.stage1_candidates - stats_.stage2_evaluations;
  stats_.kept_pairs = static_cast<int64_t>(found.size());
  if (stats_.clips == 1) {
    stats_.notes.push_back("one clip: every transition stays inside it");
    log->warn("the sprite set has one clip: every transition stays inside it");
  }
  log->info(
      "{} sprites in {} clips: {} stage-1 candidates, {} stage-2 evaluations, {} kept pairs "
      "({:.2f} s)",
      n, stats_.clips, stats_.stage1_candidates, stats_.stage2_evaluations, stats_.kept_pairs,
      stats_.seconds_images + stats_.seconds_index + stats_.seconds_pairs);
}

TransitionDelta TransitionBuilder::Add(std::span<const SpriteInput> sprites) {
  TransitionDelta delta;
  if (sprites.empty()) return delta;
  const int32_t first = store_.Append(sprites, 1);
  neighbours_.resize(store_.size());
  std::vector<int32_t> hits;
  for (int32_t s = first; s < store_.size(); ++s) {
    hits.clear();
    index_.Query(store_.cheap(s), &hits);  // every earlier sprite, none later
    index_.Insert(store_.cheap(s));
    stats_.stage1_candidates += static_cast<int64_t>(hits.size());
    auto& mine = neighbours_[s];
    for (size_t h = 0; h < hits.size(); ++h) {
      if (h + 8 < hits.size()) store_.PrefetchCoarse(hits[h + 8]);
      const int32_t j = hits[h];
      double d;
      if (!Compare(s, j, &d)) continue;
      mine.push_back({j, d});
      InsertNeighbour(j, s, d);
      const int64_t a = store_.id(s), b = store_.id(j);
      delta.pairs.push_back({std::min(a, b), std::max(a, b), d});
    }
    std::sort(mine.begin(), mine.end(),
              [](const Neighbour& a, const Neighbour& b) { return a.index < b.index; });
    stats_.kept_pairs += static_cast<int64_t>(mine.size());
    // New transitions: out of the clip end that s extends, and into s.
    const int32_t p = store_.prev(s);
    if (p >= 0) {
      TransitionsFrom(p, &delta.transitions);
      TransitionsInto(s, &delta.transitions);
    }
  }
  stats_.sprites = store_.size();
  stats_.clips = static_cast<int64_t>(store_.clip_count());
  return delta;
}

int32_t TransitionBuilder::AppendIndexOnly(std::span<const SpriteInput> sprites, int threads) {
  if (sprites.empty()) return store_.size();
  const int32_t first = store_.Append(sprites, threads);
  neighbours_.resize(store_.size());
  for (int32_t s = first; s < store_.size(); ++s) index_.Insert(store_.cheap(s));
  stats_.sprites = store_.size();
  stats_.clips = static_cast<int64_t>(store_.clip_count());
  return first;
}

TransitionDelta TransitionBuilder::AddPairsOf(int32_t first, int32_t end) {
  TransitionDelta delta;
  std::vector<int32_t> hits;
  for (int32_t s = first; s < end; ++s) {
    hits.clear();
    index_.Query(store_.cheap(s), &hits);
    stats_.stage1_candidates += static_cast<int64_t>(hits.size());
    for (size_t h = 0; h < hits.size(); ++h) {
      if (h + 8 < hits.size()) store_.PrefetchCoarse(hits[h + 8]);
      const int32_t j = hits[h];
      if (j == s || (j >= first && j < end && j > s)) continue;  // within the range: each pair once
      if (Find(neighbours_[s], j)) continue;                     // found by an earlier unit here
      double d;
      if (!Compare(s, j, &d)) continue;
      InsertNeighbour(s, j, d);
      InsertNeighbour(j, s, d);
      ++stats_.kept_pairs;
      const int64_t a = store_.id(s), b = store_.id(j);
      delta.pairs.push_back({std::min(a, b), std::max(a, b), d});
    }
  }
  for (int32_t i = first; i < end; ++i) {
    TransitionsFrom(i, &delta.transitions);
    TransitionsInto(i, &delta.transitions);
  }
  std::sort(delta.transitions.begin(), delta.transitions.end(),
            [](const Transition& a, const Transition& b) {
              return a.from != b.from ? a.from < b.from : a.to < b.to;
            });
  delta.transitions.erase(std::unique(delta.transitions.begin(), delta.transitions.end(),
                                      [](const Transition& a, const Transition& b) {
                                        return a.from == b.from && a.to == b.to;
                                      }),
                          delta.transitions.end());
  return delta;
}

void TransitionBuilder::TransitionsFrom(int32_t i, std::vector<Transition>* out) const {
  const int32_t successor = store_.next(i);
  if (successor < 0) return;  // a clip's last frame: no i+1, no transition out
  const auto& mine = neighbours_[i];
  for (const Neighbour& n : neighbours_[successor]) {  // {i+1, j} kept
    const int32_t j = n.index;
    const int32_t before_j = store_.prev(j);
    if (before_j < 0) continue;               // j is a clip's first frame: no j-1
    const Neighbour* direct = Find(mine, j);  // {i, j} kept (never true for j == i)
    if (!direct) continue;
    if (const Neighbour* m = Find(mine, before_j)) {  // {i, j-1} kept
      out->push_back({store_.id(i), store_.id(j), direct->distance, n.distance + m->distance});
    }
  }
}

void TransitionBuilder::TransitionsInto(int32_t j, std::vector<Transition>* out) const {
  const int32_t before_j = store_.prev(j);
  if (before_j < 0) return;  // a clip's first frame: no j-1, no transition in
  const auto& before = neighbours_[before_j];
  const auto& mine = neighbours_[j];
  for (const Neighbour& n : mine) {  // {i+1, j} kept with i+1 = n.index
    const int32_t i = store_.prev(n.index);
    if (i < 0) continue;
    const Neighbour* direct = Find(mine, i);  // {i, j} kept (never true for i == j)
    if (!direct) continue;
    if (const Neighbour* m = Find(before, i)) {  // {i, j-1} kept
      out->push_back({store_.id(i), store_.id(j), direct->distance, n.distance + m->distance});
    }
  }
}

std::vector<KeptPair> TransitionBuilder::KeptPairs() const {
  std::vector<KeptPair> out;
  for (int32_t i = 0; i < store_.size(); ++i) {
    for (const Neighbour& n : neighbours_[i]) {
      const int64_t a = store_.id(i), b = store_.id(n.index);
      if (a < b) out.push_back({a, b, n.distance});
    }
  }
  std::sort(out.begin(), out.end(), [](const KeptPair& x, const KeptPair& y) {
    return std::tie(x.sprite_a, x.sprite_b) < std::tie(y.sprite_a, y.sprite_b);
  });
  return out;
}

std::vector<Transition> TransitionBuilder::Transitions(int max_per_sprite) const {
  std::vector<Transition> out, mine;
  for (int32_t i = 0; i < store_.size(); ++i) {
    mine.clear();
    TransitionsFrom(i, &mine);
    KeepCheapestPerSprite(&mine, max_per_sprite);
    out.insert(out.end(), mine.begin(), mine.end());
  }
  std::sort(out.begin(), out.end(), [](const Transition& x, const Transition& y) {
    return std::tie(x.from, x.to) < std::tie(y.from, y.to);
  });
  return out;
}

int64_t TransitionBuilder::TransitionCount() const {
  std::vector<Transition> scratch;
  int64_t count = 0;
  for (int32_t i = 0; i < store_.size(); ++i) {
    scratch.clear();
    TransitionsFrom(i, &scratch);
    count += static_cast<int64_t>(scratch.size());
  }
  return count;
}

}  // namespace ss
