#include "animate/skeleton/match_dp.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <memory>
#include <new>
#include <sstream>
#include <utility>

#include <sys/mman.h>

#include "core/error.h"
#include "core/log.h"

// GCC notes that 32-byte vector arguments change the ABI without AVX; these helpers are
// inline and never cross a library boundary.
#pragma GCC diagnostic ignored "-Wpsabi"

namespace ss {

bool MatchOptions::IsValid(std::string* why) const {
  auto fail = [&](const std::string& reason) {
    if (why) *why = reason;
    return false;
  };
  for (float v : {skip_cost, jump_cost, freeze_cost, stutter_cost}) {
    if (!(v >= 0) || !std::isfinite(v))
      return fail("skip, jump, freeze and stutter costs must be finite and >= 0");
  }
  if (max_forward_step < 1 || max_forward_step > 64)
    return fail("max_forward_step must be within 1..64");
  if (stutter_window < 0 || stutter_window > 64) return fail("stutter_window must be within 0..64");
  if (freeze_levels < 1 || freeze_levels > 7) return fail("freeze_levels must be within 1..7");
  if (skip_cost * static_cast<float>(max_forward_step - 1) > jump_cost) {
    return fail(
        "a forward skip may not cost more than a jump: skip_cost * (max_forward_step - 1) <= "
        "jump_cost");
  }
  for (size_t i = 0; i < transitions.size(); ++i) {
    if (!(transitions[i].cost >= 0) || !std::isfinite(transitions[i].cost)) {
      return fail("transitions[" + std::to_string(i) + "].cost must be finite and >= 0");
    }
  }
  return true;
}

MatchOptions MatchOptions::WithoutPenalties() const {
  MatchOptions o = *this;
  o.freeze_cost = 0;
  o.stutter_cost = 0;
  return o;
}

std::string MatchResult::Summary() const {
  std::ostringstream s;
  s << source_frames.size() << " target frames, cost " << total_cost << " (matching "
    << matching_cost << "), " << stats.freezes << " freezes in " << stats.freeze_runs
    << " runs (longest " << stats.longest_freeze << "), " << stats.stutters << " stutters, "
    << stats.skips << " skips, " << stats.jumps << " jumps, " << stats.listed << " listed; "
    << cost_seconds << " s costs, " << forward_seconds << " s forward, " << backward_seconds
    << " s backward, " << memory_bytes / (1 << 20) << " MiB ("
    << (walked_decisions ? "decisions" : "checkpoints") << ")";
  return s.str();
}

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr int kLanes = 8;
constexpr int kCostTile = 16;  // target rows of costs computed at once

typedef float v8f __attribute__((vector_size(32)));
typedef int v8i __attribute__((vector_size(32)));
typedef uint8_t v8u8 __attribute__((vector_size(8)));
typedef uint16_t v8u16 __attribute__((vector_size(16)));

// What a step records per cell. The low byte always holds argmin_r V(s, r) (bits 0-2) and
// whether V(s, R) came from r = R-1 (bit 3). kPacked adds the move into (s, 0) in bits
// 4-7; kWide stores 2 bytes a cell, the move in the second. Move codes: 0 none (V(s,0) is
// +inf), k = 1..Kf advance by k, Kf + k (k = 1..W) stutter back by k, Kf + W + 1 a jump
// (global: the first entry of the previous row's top list outside [s, s+W]; local: the
// row's stored jump source). A listed transition that wins is kept aside per row.
enum RecordMode { kArgOnly = 1, kPacked = 2, kWide = 3 };

inline v8f Load(const float* p) {
  v8f v;
  std::memcpy(&v, p, sizeof(v));
  return v;
}
inline void Store(float* p, v8f v) { std::memcpy(p, &v, sizeof(v)); }
inline v8f Min(v8f a, v8f b) { return a < b ? a : b; }
inline float Min(float a, float b) { return a < b ? a : b; }

// Checks the clip (or movement) starts of `count` frames.
void CheckStarts(const std::vector<int>& starts, int count, const std::string& what) {
  if (starts.empty() || starts.front() != 0) throw InputError(what, "must start with 0");
  for (size_t i = 1; i < starts.size(); ++i) {
    if (starts[i] <= starts[i - 1]) throw InputError(what, "must be ascending");
  }
  if (starts.back() >= count) {
    throw InputError(what, "start " + std::to_string(starts.back()) + " is beyond the " +
                               std::to_string(count) + " frames");
  }
}

// Segment id of every frame.
std::vector<int> SegmentIds(const std::vector<int>& starts, int count) {
  std::vector<int> id(count);
  for (size_t g = 0; g < starts.size(); ++g) {
    const int end = g + 1 < starts.size() ? starts[g + 1] : count;
    std::fill(id.begin() + starts[g], id.begin() + end, static_cast<int>(g));
  }
  return id;
}

// The rules of one kind of row: free rows (pass one, and the first frame of each target
// movement) or rows inside a target movement (the refinement's second pass).
struct RowRules {
  std::vector<int> seg_begin,
      seg_end;  // segments: clips (free) or source movements (inside), end inclusive
  std::vector<float> fwd_limit;          // per s: forward steps allowed, min(Kf, s - segment begin)
  std::vector<float> back_limit;         // per s: backward steps allowed, min(W, segment end - s)
  std::vector<SourceTransition> listed;  // applicable transitions, sorted by `to`
  std::vector<int> listed_begin;  // listed transitions into s: [listed_begin[s], listed_begin[s+1])
  std::vector<int> edges;         // s where a limit is below Kf or W (near a segment's ends)
  bool local_jumps = false;       // jumps stay inside the segment and cost λ per frame more
};

RowRules MakeRules(const std::vector<int>& starts, int count, const MatchOptions& o, bool local) {
  RowRules rules;
  rules.local_jumps = local;
  rules.fwd_limit.resize(count);
  rules.back_limit.resize(count);
  const std::vector<int> seg = SegmentIds(starts, count);
  for (size_t g = 0; g < starts.size(); ++g) {
    const int begin = starts[g];
    const int end = (g + 1 < starts.size() ? starts[g + 1] : count) - 1;
    rules.seg_begin.push_back(begin);
    rules.seg_end.push_back(end);
    for (int s = begin; s <= end; ++s) {
      rules.fwd_limit[s] = static_cast<float>(std::min(o.max_forward_step, s - begin));
      rules.back_limit[s] = static_cast<float>(std::min(o.stutter_window, end - s));
      if (s - begin < o.max_forward_step || end - s < o.stutter_window) rules.edges.push_back(s);
    }
  }
  for (const auto& tr : o.transitions) {
    if (tr.from == tr.to) continue;
    if (local && seg[tr.from] != seg[tr.to]) continue;
    rules.listed.push_back(tr);
  }
  std::stable_sort(
      rules.listed.begin(), rules.listed.end(),
      [](const SourceTransition& a, const SourceTransition& b) { return a.to < b.to; });
  rules.listed_begin.assign(count + 1, 0);
  for (const auto& tr : rules.listed) ++rules.listed_begin[tr.to + 1];
  for (int s = 0; s < count; ++s) rules.listed_begin[s + 1] += rules.listed_begin[s];
  return rules;
}

struct TopEntry {
  float value;
  int index;
};

// One DP row: V(s, r) for r = 0..R, M(s) = min_r V(s, r), padded with +inf on both sides
// so the move windows never leave the array.
struct Row {
  std::vector<float> v;          // [r * stride + s]
  std::vector<float> m_storage;  // pad + stride + pad
  float* m = nullptr;
  float min = kInf;           // min_s M(s)
  std::vector<TopEntry> top;  // the smallest M(s), ascending

  void Allocate(int levels, size_t stride, int pad) {
    v.assign(static_cast<size_t>(levels + 1) * stride, kInf);
    m_storage.assign(stride + 2 * pad, kInf);
    m = m_storage.data() + pad;
  }
};

// Arguments of the vectorized row step.
struct StepArgs {
  const float* cost;   // c_t(s)
  const float* m;      // M_{t-1}(s), padded
  const float* vprev;  // V_{t-1}(s, r), [r * stride + s]
  float* vcur;
  float* mcur;
  uint8_t* record;  // nullptr, or per s what `mode` says (RecordMode)
  int mode;         // RecordMode when record is set
  const float* fwd_limit;
  const float* back_limit;
  const float* jump;     // per s (local jumps) or nullptr
  float jump_const;      // J + min M outside the window (global jumps; fixed up later where wrong)
  const float* skip;     // [k], k = 1..Kf
  const float* stutter;  // [k], k = 1..W
  const float* freeze;   // [r], r = 1..R
  int kf, w, levels;
  size_t stride;
  int count;     // s in [0, count), count a multiple of kLanes
  float offset;  // subtracted from every value (the previous row's minimum)
  bool masked;   // apply fwd_limit / back_limit; false: the caller redoes the edges
};

// The row step; kMasked = false ignores the segment limits (every window full), for rules
// whose few edge cells the caller recomputes with Cell().
// kMode: 0 (no record) or a RecordMode. The move codes take the first candidate that
// reaches the minimum in the order advance k = 1..Kf, stutter k = 1..W, jump (as the
// backtrack by comparison did); the values are computed exactly as without them.
template <bool kMasked, int kMode>
__attribute__((always_inline)) inline void StepBody(const StepArgs& args) {
  // A local copy: the stores through float pointers below could alias the caller's struct
  // (it holds floats), which made the compiler reload every field in the loop.
  const StepArgs a = args;
  const int levels = a.levels;
  const v8f inf = v8f{} + kInf;
  constexpr bool kMoves = kMode == kPacked || kMode == kWide;
  const v8i jump_code = v8i{} + (a.kf + a.w + 1);
  for (int s = 0; s < a.count; s += kLanes) {
    v8f fwd = inf;
    v8f stu = inf;
    v8i fcode{};
    if constexpr (kMasked) {
      const v8f fl = Load(a.fwd_limit + s);
      for (int k = 1; k <= a.kf; ++k) {
        const v8f cand = Load(a.m + s - k) + a.skip[k];
        const v8i ok = (v8f{} + static_cast<float>(k)) <= fl;
        if constexpr (kMoves) fcode = (ok & (cand < fwd)) ? v8i{} + k : fcode;
        fwd = ok ? Min(fwd, cand) : fwd;
      }
      const v8f bl = Load(a.back_limit + s);
      for (int k = 1; k <= a.w; ++k) {
        const v8f cand = Load(a.m + s + k) + a.stutter[k];
        stu = (v8f{} + static_cast<float>(k)) <= bl ? Min(stu, cand) : stu;
      }
    } else {
      for (int k = 1; k <= a.kf; ++k) {
        const v8f cand = Load(a.m + s - k) + a.skip[k];
        if constexpr (kMoves) fcode = cand < fwd ? v8i{} + k : fcode;
        fwd = Min(fwd, cand);
      }
      for (int k = 1; k <= a.w; ++k) stu = Min(stu, Load(a.m + s + k) + a.stutter[k]);
    }
    const v8f jmp = a.jump ? Load(a.jump + s) : v8f{} + a.jump_const;
    const v8f best = Min(fwd, Min(stu, jmp));
    v8i move{};
    if constexpr (kMoves) {
      const v8i stu_first = stu < fwd;
      const v8i jump_first = jmp < (stu_first ? stu : fwd);
      move = jump_first ? jump_code : fcode;
      // A stutter seldom wins (on free rows only where the row minimum lies in the window,
      // cells Step redoes anyway), so its k is looked for only when one does.
      const v8i stutters = stu_first & ~jump_first;
      const v8u8 lanes = __builtin_convertvector(stutters, v8u8);
      uint64_t any;
      std::memcpy(&any, &lanes, sizeof(any));
      if (any != 0) {
        v8f first = inf;
        v8i scode{};
        for (int k = 1; k <= a.w; ++k) {
          const v8f cand = Load(a.m + s + k) + a.stutter[k];
          v8i ok = v8i{} - 1;
          if constexpr (kMasked) ok = (v8f{} + static_cast<float>(k)) <= Load(a.back_limit + s);
          scode = (ok & (cand < first)) ? v8i{} + (a.kf + k) : scode;
          first = ok ? Min(first, cand) : first;
        }
        move = stutters ? scode : move;
      }
    }
    const v8f c = Load(a.cost + s) - a.offset;
    const v8f v0 = c + best;
    Store(a.vcur + s, v0);
    v8f mm = v0;
    v8i arg{};
    for (int r = 1; r < levels; ++r) {
      const v8f vr = (c + a.freeze[r]) + Load(a.vprev + (r - 1) * a.stride + s);
      Store(a.vcur + r * a.stride + s, vr);
      arg = vr < mm ? v8i{} + r : arg;
      mm = Min(mm, vr);
    }
    const v8f below = Load(a.vprev + (levels - 1) * a.stride + s);
    const v8f at = Load(a.vprev + levels * a.stride + s);
    const v8i from_below = below <= at;
    const v8f vtop = (c + a.freeze[levels]) + Min(below, at);
    Store(a.vcur + levels * a.stride + s, vtop);
    arg = vtop < mm ? v8i{} + levels : arg;
    mm = Min(mm, vtop);
    Store(a.mcur + s, mm);
    if constexpr (kMode == kArgOnly || kMode == kPacked) {
      const v8i code =
          kMode == kPacked ? (arg | (from_below & 8) | (move << 4)) : (arg | (from_below & 8));
      const v8u8 bytes = __builtin_convertvector(code, v8u8);  // one 8-byte store, not eight
      std::memcpy(a.record + s, &bytes, sizeof(bytes));
    } else if constexpr (kMode == kWide) {
      const v8u16 words = __builtin_convertvector(arg | (from_below & 8) | (move << 8), v8u16);
      std::memcpy(a.record + 2 * static_cast<size_t>(s), &words,
                  sizeof(words));  // little endian: low byte first
    }
  }
}

template <bool kMasked>
__attribute__((always_inline)) inline void StepModes(const StepArgs& args) {
  if (!args.record) return StepBody<kMasked, 0>(args);
  switch (args.mode) {
    case kArgOnly:
      return StepBody<kMasked, kArgOnly>(args);
    case kPacked:
      return StepBody<kMasked, kPacked>(args);
    default:
      return StepBody<kMasked, kWide>(args);
  }
}

__attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default"))) void StepKernel(
    const StepArgs& args) {
  if (args.masked) {
    StepModes<true>(args);
  } else {
    StepModes<false>(args);
  }
}

double Seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

class Engine {
 public:
  Engine(const CostRows& costs, const std::vector<int>& clip_starts, const MatchOptions& options,
         const MovementConstraint* movements);
  MatchResult Solve();

 private:
  bool Inside(int t) const { return inside_row_.empty() ? false : inside_row_[t] != 0; }
  const RowRules& Rules(int t) const { return Inside(t) ? inside_ : free_; }
  void ComputeCosts(int t0, int n, double* seconds);
  // Row t's costs, computing the tile of up to kCostTile rows from t (not past `end`) first
  // when t is not in the current one.
  const float* CostRow(int t, int end) {
    if (t >= tile_first_ + tile_count_ || t < tile_first_)
      ComputeCosts(t, std::min(kCostTile, end - t), &cost_seconds_);
    return tile_.data() + static_cast<size_t>(t - tile_first_) * S_;
  }
  void Init(const float* c, Row* row, uint8_t* record);
  // One row; `record` (nullptr: none) receives what mode_ says. With moves recorded, a
  // listed transition that wins the cell goes to listed_choice_, and a local row's jump
  // sources to `jump_source`.
  void Step(int t, const float* c, const Row& prev, Row* cur, uint8_t* record,
            int32_t* jump_source = nullptr);
  // The scalar cell update (tail and fix-ups); `jump` = J + the best allowed jump source.
  void Cell(int s, const float* c, const Row& prev, const RowRules& rules, float jump, Row* cur,
            uint8_t* record) const;
  // Into `out` J plus the best local jump into each s; its source into `source` if given.
  void LocalJumps(const RowRules& rules, const float* m, float* out, int32_t* source);
  void Finish(Row* row, int t) const;
  // Best jump value into s from a row's top list (global jumps); +inf if none.
  float GlobalJump(const std::vector<TopEntry>& top, int s, const RowRules& rules) const;
  // The state at t-1 that the optimal path into (t, s, r) comes from.
  std::pair<int, int> Predecessor(int t, int s, int r, const float* m_prev, const uint8_t* rec_prev,
                                  const uint8_t* rec_cur,
                                  const std::vector<TopEntry>& top_prev) const;
  void StateFromCheckpoint(const std::vector<float>& v, Row* row, uint8_t* record) const;
  bool MovesRecorded() const { return mode_ == kPacked || mode_ == kWide; }
  int RecordBytes() const { return mode_ == kWide ? 2 : 1; }
  // Backtrack through decisions stored by the forward pass; false when they would not fit
  // the budget (nothing done then).
  bool SolveWithDecisions(MatchResult* result);
  void SolveWithCheckpoints(MatchResult* result);

  const CostRows& costs_;
  const MatchOptions& o_;
  const MovementConstraint* movements_;
  int T_ = 0, S_ = 0, R_ = 0;
  size_t stride_ = 0;
  int pad_ = 0;
  RowRules free_, inside_;
  std::vector<uint8_t> inside_row_;
  std::vector<float> skip_, stutter_, freeze_, local_stutter_;
  std::vector<float> tile_;
  int tile_first_ = -1, tile_count_ = 0;
  std::vector<float> jump_, suffix_;
  std::vector<int32_t> suffix_at_;  // where suffix_[x] is reached (LocalJumps with sources)
  double cost_seconds_ = 0;
  int mode_ = kArgOnly;                             // what Step and Cell record (RecordMode)
  std::vector<std::pair<int, int>> listed_choice_;  // (s, from) of cells a listed transition wins
};

Engine::Engine(const CostRows& costs, const std::vector<int>& clip_starts,
               const MatchOptions& options, const MovementConstraint* movements)
    : costs_(costs), o_(options), movements_(movements) {
  std::string why;
  if (!options.IsValid(&why)) throw InputError("match options", why);
  T_ = costs.targets();
  S_ = costs.sources();
  R_ = options.freeze_levels;
  if (S_ <= 0) throw InputError("sources", "no source frame to match against");
  CheckStarts(clip_starts, S_, "clip starts");
  for (size_t i = 0; i < options.transitions.size(); ++i) {
    const auto& tr = options.transitions[i];
    if (tr.from < 0 || tr.from >= S_ || tr.to < 0 || tr.to >= S_) {
      throw InputError("transitions[" + std::to_string(i) + "]",
                       "frame out of range 0.." + std::to_string(S_ - 1));
    }
  }
  stride_ = (static_cast<size_t>(S_) + kLanes - 1) / kLanes * kLanes;
  pad_ = std::max(o_.max_forward_step, o_.stutter_window) + kLanes;
  free_ = MakeRules(clip_starts, S_, o_, false);
  skip_.assign(o_.max_forward_step + 1, 0.0f);
  for (int k = 2; k <= o_.max_forward_step; ++k)
    skip_[k] = o_.skip_cost * static_cast<float>(k - 1);
  stutter_.assign(o_.stutter_window + 1, o_.jump_cost + o_.stutter_cost);
  freeze_.assign(R_ + 1, 0.0f);
  for (int r = 1; r <= R_; ++r) freeze_[r] = o_.freeze_cost * static_cast<float>(r);
  if (movements_) {
    const auto& m = *movements_;
    if (!(m.jump_cost_per_frame >= 0) || !std::isfinite(m.jump_cost_per_frame)) {
      throw InputError("movement constraint", "jump_cost_per_frame must be finite and >= 0");
    }
    CheckStarts(m.source_starts, S_, "source movement starts");
    for (int c : clip_starts) {
      if (!std::binary_search(m.source_starts.begin(), m.source_starts.end(), c)) {
        throw InputError("source movement starts",
                         "clip start " + std::to_string(c) + " is not a movement start");
      }
    }
    if (T_ > 0) CheckStarts(m.target_starts, T_, "target movement starts");
    inside_ = MakeRules(m.source_starts, S_, o_, true);
    inside_row_.assign(T_, 1);
    for (int t : m.target_starts) inside_row_[t] = 0;
    if (T_ > 0) inside_row_[0] = 0;
    local_stutter_.assign(o_.stutter_window + 1, 0.0f);
    for (int k = 1; k <= o_.stutter_window; ++k) {
      local_stutter_[k] =
          (o_.jump_cost + o_.stutter_cost) + m.jump_cost_per_frame * static_cast<float>(k);
    }
    jump_.assign(stride_, kInf);
    suffix_.assign(S_ + 1, kInf);
    suffix_at_.assign(S_ + 1, -1);
  }
}

void Engine::ComputeCosts(int t0, int n, double* seconds) {
  const auto start = std::chrono::steady_clock::now();
  tile_.resize(static_cast<size_t>(kCostTile) * S_ + kLanes);
  costs_.Compute(t0, n, tile_.data());
  tile_first_ = t0;
  tile_count_ = n;
  *seconds += Seconds(start);
}

void Engine::Init(const float* c, Row* row, uint8_t* record) {
  std::fill(row->v.begin(), row->v.end(), kInf);
  std::copy(c, c + S_, row->v.begin());
  std::copy(c, c + S_, row->m);
  if (record) std::fill(record, record + static_cast<size_t>(S_) * RecordBytes(), 0);
  Finish(row, 0);
}

void Engine::Finish(Row* row, int t) const {
  const size_t keep = static_cast<size_t>(o_.stutter_window) + 2;
  auto& top = row->top;
  top.clear();
  const float* m = row->m;
  constexpr int kBlock = 64;
  for (int b = 0; b < S_; b += kBlock) {
    const int e = std::min(S_, b + kBlock);
    float block_min = kInf;
    for (int s = b; s < e; ++s) block_min = Min(block_min, m[s]);
    if (top.size() == keep && !(block_min < top.back().value)) continue;
    if (block_min == kInf) continue;
    for (int s = b; s < e; ++s) {
      if (!(m[s] < kInf)) continue;
      if (top.size() == keep && !(m[s] < top.back().value)) continue;
      auto it = std::upper_bound(top.begin(), top.end(), m[s],
                                 [](float v, const TopEntry& x) { return v < x.value; });
      top.insert(it, {m[s], s});
      if (top.size() > keep) top.pop_back();
    }
  }
  row->min = top.empty() ? kInf : top.front().value;
  if (!(row->min < kInf)) {
    throw WorkError("match", "no allowed path reaches target frame " + std::to_string(t) +
                                 " (every source frame is excluded or unreachable)");
  }
}

float Engine::GlobalJump(const std::vector<TopEntry>& top, int s, const RowRules& rules) const {
  const int last = s + static_cast<int>(rules.back_limit[s]);
  for (const auto& e : top) {
    if (e.index < s || e.index > last) return o_.jump_cost + e.value;
  }
  return kInf;
}

namespace {

// Engine::LocalJumps; kSources also keeps where each best jump comes from (the first
// source frame reaching it, prefix before suffix, as Predecessor() would pick).
template <bool kSources>
void LocalJumpsOf(const RowRules& rules, const float* m, float lambda, float jump, int w,
                  float* out, int32_t* source, float* suffix, int32_t* suffix_at) {
  for (size_t g = 0; g < rules.seg_begin.size(); ++g) {
    const int a = rules.seg_begin[g], b = rules.seg_end[g];
    float run = kInf;  // min over s' < s of M(s') - λ (s' - a)
    int run_at = -1;   // its first s'
    for (int s = a; s <= b; ++s) {
      out[s] = (run + lambda * static_cast<float>(s - a)) + jump;
      const float v = m[s] - lambda * static_cast<float>(s - a);
      if constexpr (kSources) {
        source[s] = run_at;
        if (v < run) run_at = s;
      }
      run = Min(run, v);
    }
    float after = kInf;  // suffix[x] = min over s' >= x of M(s') + λ (s' - a)
    int after_at = -1;   // its first s'
    suffix[b + 1] = kInf;
    if constexpr (kSources) suffix_at[b + 1] = -1;
    for (int x = b; x >= a; --x) {
      const float v = m[x] + lambda * static_cast<float>(x - a);
      if constexpr (kSources) {
        if (v <= after) after_at = x;
        suffix_at[x] = after_at;
      }
      after = Min(after, v);
      suffix[x] = after;
    }
    for (int s = a; s + w + 1 <= b; ++s) {
      const float later = (suffix[s + w + 1] - lambda * static_cast<float>(s - a)) + jump;
      if constexpr (kSources) {
        if (later < out[s]) source[s] = suffix_at[s + w + 1];  // a tie keeps the earlier source
      }
      out[s] = Min(out[s], later);
    }
  }
}

}  // namespace

void Engine::LocalJumps(const RowRules& rules, const float* m, float* out, int32_t* source) {
  const float lambda = movements_->jump_cost_per_frame;
  if (source) {
    LocalJumpsOf<true>(rules, m, lambda, o_.jump_cost, o_.stutter_window, out, source,
                       suffix_.data(), suffix_at_.data());
  } else {
    LocalJumpsOf<false>(rules, m, lambda, o_.jump_cost, o_.stutter_window, out, nullptr,
                        suffix_.data(), nullptr);
  }
}

void Engine::Cell(int s, const float* c, const Row& prev, const RowRules& rules, float jump,
                  Row* cur, uint8_t* record) const {
  const float* m = prev.m;
  const float* stutter = rules.local_jumps ? local_stutter_.data() : stutter_.data();
  const int kf = o_.max_forward_step;
  float fwd = kInf, stu = kInf;
  int fcode = 0, scode = 0;  // move codes as in StepBody
  for (int k = 1; k <= kf; ++k) {
    if (static_cast<float>(k) <= rules.fwd_limit[s]) {
      const float cand = m[s - k] + skip_[k];
      if (cand < fwd) fcode = k;
      fwd = Min(fwd, cand);
    }
  }
  for (int k = 1; k <= o_.stutter_window; ++k) {
    if (static_cast<float>(k) <= rules.back_limit[s]) {
      const float cand = m[s + k] + stutter[k];
      if (cand < stu) scode = kf + k;
      stu = Min(stu, cand);
    }
  }
  const float best = Min(fwd, Min(stu, jump));
  int move = stu < fwd ? scode : fcode;
  if (jump < (stu < fwd ? stu : fwd)) move = kf + o_.stutter_window + 1;
  const float cc = c[s] - prev.min;
  const float v0 = cc + best;
  cur->v[s] = v0;
  float mm = v0;
  int arg = 0;
  for (int r = 1; r < R_; ++r) {
    const float vr = (cc + freeze_[r]) + prev.v[(r - 1) * stride_ + s];
    cur->v[r * stride_ + s] = vr;
    if (vr < mm) arg = r;
    mm = Min(mm, vr);
  }
  const float below = prev.v[(R_ - 1) * stride_ + s], at = prev.v[R_ * stride_ + s];
  const float vtop = (cc + freeze_[R_]) + Min(below, at);
  cur->v[R_ * stride_ + s] = vtop;
  if (vtop < mm) arg = R_;
  mm = Min(mm, vtop);
  cur->m[s] = mm;
  if (record) {
    const int low = arg | (below <= at ? 8 : 0);
    if (mode_ == kWide) {
      record[2 * static_cast<size_t>(s)] = static_cast<uint8_t>(low);
      record[2 * static_cast<size_t>(s) + 1] = static_cast<uint8_t>(move);
    } else {
      record[s] = static_cast<uint8_t>(mode_ == kPacked ? low | move << 4 : low);
    }
  }
}

void Engine::Step(int t, const float* c, const Row& prev, Row* cur, uint8_t* record,
                  int32_t* jump_source) {
  const RowRules& rules = Rules(t);
  const bool local = rules.local_jumps;
  const bool moves = record && MovesRecorded();
  if (local) LocalJumps(rules, prev.m, jump_.data(), moves ? jump_source : nullptr);
  // J + the row minimum
  const float jump_const = local ? kInf : o_.jump_cost + prev.top.front().value;
  StepArgs a;
  a.cost = c;
  a.m = prev.m;
  a.vprev = prev.v.data();
  a.vcur = cur->v.data();
  a.mcur = cur->m;
  a.record = record;
  a.mode = mode_;
  a.fwd_limit = rules.fwd_limit.data();
  a.back_limit = rules.back_limit.data();
  a.jump = local ? jump_.data() : nullptr;
  a.jump_const = jump_const;
  a.skip = skip_.data();
  a.stutter = local ? local_stutter_.data() : stutter_.data();
  a.freeze = freeze_.data();
  a.kf = o_.max_forward_step;
  a.w = o_.stutter_window;
  a.levels = R_;
  a.stride = stride_;
  a.count = S_ / kLanes * kLanes;
  a.offset = prev.min;
  // Free rows have few edges (a clip's first Kf and last W frames): the kernel runs
  // unmasked and those cells are redone exactly. Movement rows (the refinement) have many.
  a.masked = local;
  StepKernel(a);
  for (int s = a.count; s < S_; ++s) {
    Cell(s, c, prev, rules, local ? jump_[s] : GlobalJump(prev.top, s, rules), cur, record);
  }
  if (!local) {
    for (int s : rules.edges) {
      if (s >= a.count) break;
      Cell(s, c, prev, rules, GlobalJump(prev.top, s, rules), cur, record);
    }
  }
  if (!local) {  // where the row minimum lies inside [s, s+W] the jump must come from elsewhere
    const int best = prev.top.front().index;
    for (int s = std::max(0, best - o_.stutter_window); s <= best && s < a.count; ++s) {
      if (best <= s + static_cast<int>(rules.back_limit[s])) {
        Cell(s, c, prev, rules, GlobalJump(prev.top, s, rules), cur, record);
      }
    }
  }
  const float* stutter = local ? local_stutter_.data() : stutter_.data();
  for (int s = 0; s < (rules.listed.empty() ? 0 : S_); ++s) {
    if (rules.listed_begin[s] == rules.listed_begin[s + 1]) continue;
    for (int l = rules.listed_begin[s]; l < rules.listed_begin[s + 1]; ++l) {
      const SourceTransition& tr = rules.listed[l];
      const float v0 = (c[s] - prev.min) + (prev.m[tr.from] + tr.cost);
      if (!(v0 < cur->v[s])) continue;
      cur->v[s] = v0;
      if (v0 < cur->m[s]) {
        cur->m[s] = v0;
        if (record)
          record[mode_ == kWide ? 2 * static_cast<size_t>(s) : s] &= static_cast<uint8_t>(~7);
      }
    }
    if (!moves) continue;
    // The move into (s, 0) as Predecessor() decides it: a listed transition wins when it is
    // below every rule move and the listed ones before it.
    float best = local ? jump_[s] : GlobalJump(prev.top, s, rules);
    for (int k = 1; k <= static_cast<int>(rules.fwd_limit[s]); ++k)
      best = Min(best, prev.m[s - k] + skip_[k]);
    for (int k = 1; k <= static_cast<int>(rules.back_limit[s]); ++k)
      best = Min(best, prev.m[s + k] + stutter[k]);
    int from = -1;
    for (int l = rules.listed_begin[s]; l < rules.listed_begin[s + 1]; ++l) {
      const float cand = prev.m[rules.listed[l].from] + rules.listed[l].cost;
      if (cand < best) {
        best = cand;
        from = rules.listed[l].from;
      }
    }
    if (from >= 0) listed_choice_.emplace_back(s, from);
  }
  Finish(cur, t);
}

std::pair<int, int> Engine::Predecessor(int t, int s, int r, const float* m_prev,
                                        const uint8_t* rec_prev, const uint8_t* rec_cur,
                                        const std::vector<TopEntry>& top_prev) const {
  if (r > 0 && r < R_) return {s, r - 1};
  if (r == R_) return {s, (rec_cur[s] & 8) ? R_ - 1 : R_};
  const RowRules& rules = Rules(t);
  float best = kInf;
  int from = -1;
  auto consider = [&](float value, int source) {
    if (value < best) {
      best = value;
      from = source;
    }
  };
  for (int k = 1; k <= static_cast<int>(rules.fwd_limit[s]); ++k)
    consider(m_prev[s - k] + skip_[k], s - k);
  const float* stutter = rules.local_jumps ? local_stutter_.data() : stutter_.data();
  for (int k = 1; k <= static_cast<int>(rules.back_limit[s]); ++k)
    consider(m_prev[s + k] + stutter[k], s + k);
  if (rules.local_jumps) {
    const float lambda = movements_->jump_cost_per_frame;
    const auto g = std::upper_bound(rules.seg_begin.begin(), rules.seg_begin.end(), s) -
                   rules.seg_begin.begin() - 1;
    const int a = rules.seg_begin[g], b = rules.seg_end[g];
    for (int x = a; x < s; ++x) {
      consider(
          ((m_prev[x] - lambda * static_cast<float>(x - a)) + lambda * static_cast<float>(s - a)) +
              o_.jump_cost,
          x);
    }
    for (int x = s + o_.stutter_window + 1; x <= b; ++x) {
      consider(
          ((m_prev[x] + lambda * static_cast<float>(x - a)) - lambda * static_cast<float>(s - a)) +
              o_.jump_cost,
          x);
    }
  } else {
    const int last = s + static_cast<int>(rules.back_limit[s]);
    for (const auto& e : top_prev) {
      if (e.index < s || e.index > last) {
        consider(o_.jump_cost + e.value, e.index);
        break;
      }
    }
  }
  for (int l = rules.listed_begin[s]; l < rules.listed_begin[s + 1]; ++l) {
    consider(m_prev[rules.listed[l].from] + rules.listed[l].cost, rules.listed[l].from);
  }
  if (from < 0)
    throw WorkError("match", "backtracking lost the path at target frame " + std::to_string(t));
  return {from, rec_prev[from] & 7};
}

void Engine::StateFromCheckpoint(const std::vector<float>& v, Row* row, uint8_t* record) const {
  row->v = v;
  for (int s = 0; s < S_; ++s) {
    float mm = v[s];
    int arg = 0;
    for (int r = 1; r <= R_; ++r) {
      const float x = v[r * stride_ + s];
      if (x < mm) arg = r;
      mm = Min(mm, x);
    }
    row->m[s] = mm;
    record[s] = static_cast<uint8_t>(arg);
  }
}

MatchResult Engine::Solve() {
  MatchResult result;
  if (T_ == 0) return result;
  if (!SolveWithDecisions(&result)) SolveWithCheckpoints(&result);
  return result;
}

// MemAvailable of /proc/meminfo, in bytes; the largest size_t when it cannot be read.
size_t AvailableMemoryBytes() {
  std::ifstream meminfo("/proc/meminfo");
  std::string key;
  size_t kib = 0;
  std::string unit;
  while (meminfo >> key >> kib >> unit) {
    if (key == "MemAvailable:") return kib * 1024;
  }
  return std::numeric_limits<size_t>::max();
}

bool Engine::SolveWithDecisions(MatchResult* out) {
  mode_ = o_.max_forward_step + o_.stutter_window + 1 <= 15 ? kPacked : kWide;
  const size_t row_bytes = static_cast<size_t>(S_) * RecordBytes();
  const size_t top_size = static_cast<size_t>(o_.stutter_window) + 2;
  // Rows inside a target movement keep each cell's local jump source.
  std::vector<int> local_row(T_, -1);
  int local_rows = 0;
  for (int t = 1; t < T_; ++t) {
    if (Rules(t).local_jumps) local_row[t] = local_rows++;
  }
  const size_t need = static_cast<size_t>(T_) * row_bytes +
                      static_cast<size_t>(local_rows) * S_ * sizeof(int32_t) +
                      static_cast<size_t>(T_) * top_size * sizeof(int32_t);
  // Within the budget and within half the memory the system has available now: the pages
  // are populated at once, and under overcommit an mmap past what is there would not fail
  // but get the process killed instead of falling back.
  const size_t limit = std::min(o_.max_decision_bytes, AvailableMemoryBytes() / 2);
  if (need > limit) {
    mode_ = kArgOnly;
    return false;
  }
  // the forward pass includes the store's pages
  const auto start = std::chrono::steady_clock::now();
  // The decisions, then the jump sources, mapped with their pages at once (MAP_POPULATE):
  // a page fault at a time made the forward pass visibly slower (+39 % instead of +7 %
  // over no store at 2,000 x 100,000). Every byte is written by its row's step.
  const size_t decision_bytes = (static_cast<size_t>(T_) * row_bytes + 63) / 64 * 64;
  const size_t map_bytes = decision_bytes + static_cast<size_t>(local_rows) * S_ * sizeof(int32_t);
  void* map = mmap(nullptr, map_bytes, PROT_READ | PROT_WRITE,
                   MAP_PRIVATE | MAP_ANONYMOUS | MAP_POPULATE, -1, 0);
  if (map == MAP_FAILED) {
    mode_ = kArgOnly;
    return false;
  }
  const auto unmap = [map_bytes](uint8_t* p) { munmap(p, map_bytes); };
  const std::unique_ptr<uint8_t[], decltype(unmap)> decisions(static_cast<uint8_t*>(map), unmap);
  int32_t* const jump_sources = reinterpret_cast<int32_t*>(decisions.get() + decision_bytes);
  std::vector<int32_t> tops(static_cast<size_t>(T_) * top_size,
                            -1);                // each row's top list, its indices
  std::vector<size_t> listed_begin(T_ + 1, 0);  // row t's listed choices
  listed_choice_.clear();
  MatchResult& result = *out;
  Row rows[2];
  for (auto& r : rows) r.Allocate(R_, stride_, pad_);
  double offset = 0;  // sum of the row minima subtracted on the way
  int cur = 0;
  for (int t = 0; t < T_; ++t) {
    const float* c = CostRow(t, T_);
    uint8_t* record = decisions.get() + static_cast<size_t>(t) * row_bytes;
    listed_begin[t] = listed_choice_.size();
    if (t == 0) {
      Init(c, &rows[cur], record);
    } else {
      offset += rows[1 - cur].min;
      Step(t, c, rows[1 - cur], &rows[cur], record,
           local_row[t] >= 0 ? jump_sources + static_cast<size_t>(local_row[t]) * S_ : nullptr);
    }
    // The cells listed transitions win are kept aside (8 bytes each); should they push the
    // store past the limit (a bank whose transitions win most cells), start over without.
    if (need + listed_choice_.capacity() * sizeof(listed_choice_[0]) > limit) {
      Log("animate.match")
          ->warn(
              "{} x {}: the listed transitions' choices pass the decision budget at row {}; "
              "solving again with checkpoints",
              T_, S_, t);
      std::vector<std::pair<int, int>>().swap(listed_choice_);
      cost_seconds_ = 0;  // the checkpoint pass times its own costs
      mode_ = kArgOnly;
      return false;
    }
    const auto& top = rows[cur].top;
    for (size_t i = 0; i < top.size() && i < top_size; ++i) tops[t * top_size + i] = top[i].index;
    cur = 1 - cur;
  }
  listed_begin[T_] = listed_choice_.size();
  result.total_cost = offset + rows[1 - cur].min;
  result.forward_seconds = Seconds(start) - cost_seconds_;

  // Backward: a walk over the stored decisions.
  const auto back_start = std::chrono::steady_clock::now();
  const int kf = o_.max_forward_step, w = o_.stutter_window;
  const auto low = [&](int t, int s) {
    return decisions[static_cast<size_t>(t) * row_bytes + s * RecordBytes()];
  };
  const auto move = [&](int t, int s) {
    const uint8_t* rec = decisions.get() + static_cast<size_t>(t) * row_bytes;
    return mode_ == kWide ? static_cast<int>(rec[2 * static_cast<size_t>(s) + 1]) : rec[s] >> 4;
  };
  result.source_frames.assign(T_, 0);
  const float* m_last = rows[1 - cur].m;
  int s = static_cast<int>(std::min_element(m_last, m_last + S_) - m_last);
  int r = low(T_ - 1, s) & 7;
  for (int t = T_ - 1;; --t) {
    result.source_frames[t] = s;
    if (t == 0) break;
    if (r > 0 && r < R_) {
      --r;
      continue;
    }
    if (r == R_) {
      r = (low(t, s) & 8) ? R_ - 1 : R_;
      continue;
    }
    int from = -1;
    const auto first = listed_choice_.begin() + static_cast<std::ptrdiff_t>(listed_begin[t]);
    const auto last = listed_choice_.begin() + static_cast<std::ptrdiff_t>(listed_begin[t + 1]);
    const auto listed =
        std::lower_bound(first, last, std::make_pair(s, std::numeric_limits<int>::min()));
    if (listed != last && listed->first == s) {
      from = listed->second;
    } else {
      const int code = move(t, s);
      const RowRules& rules = Rules(t);
      if (code >= 1 && code <= kf) {
        from = s - code;
      } else if (code > kf && code <= kf + w) {
        from = s + (code - kf);
      } else if (code == kf + w + 1 && rules.local_jumps) {
        from = jump_sources[static_cast<size_t>(local_row[t]) * S_ + s];
      } else if (code == kf + w + 1) {
        const int window_end = s + static_cast<int>(rules.back_limit[s]);
        for (size_t i = 0; i < top_size; ++i) {
          const int e = tops[(t - 1) * top_size + i];
          if (e < 0) break;
          if (e < s || e > window_end) {
            from = e;
            break;
          }
        }
      }
    }
    if (from < 0 || from >= S_) {
      throw WorkError("match", "backtracking lost the path at target frame " + std::to_string(t));
    }
    s = from;
    r = low(t - 1, s) & 7;
  }
  result.cost_seconds = cost_seconds_;
  result.backward_seconds = Seconds(back_start);
  result.memory_bytes = map_bytes + tops.size() * sizeof(int32_t) +
                        listed_begin.size() * sizeof(size_t) +
                        listed_choice_.capacity() * sizeof(listed_choice_[0]);
  result.walked_decisions = true;
  mode_ = kArgOnly;
  return true;
}

void Engine::SolveWithCheckpoints(MatchResult* out) {
  MatchResult& result = *out;
  mode_ = kArgOnly;
  const auto start = std::chrono::steady_clock::now();
  // Block length K balances the checkpoints ((T/K) rows of (R+1) floats per source) and one
  // block of M rows and record bytes (K rows of 5 bytes per source).
  const int block =
      std::clamp(static_cast<int>(std::lround(std::sqrt(T_ * 4.0 * (R_ + 1) / 5.0))), 1, T_);
  const int blocks = (T_ + block - 1) / block;
  std::vector<std::vector<float>> checkpoints(blocks - 1);
  Row rows[2];
  for (auto& r : rows) r.Allocate(R_, stride_, pad_);
  double offset = 0;  // sum of the row minima subtracted on the way
  int cur = 0;
  for (int t = 0; t < T_; ++t) {
    const float* c = CostRow(t, T_);
    if (t == 0) {
      Init(c, &rows[cur], nullptr);
    } else {
      offset += rows[1 - cur].min;
      Step(t, c, rows[1 - cur], &rows[cur], nullptr);
    }
    if ((t + 1) % block == 0 && (t + 1) / block < blocks)
      checkpoints[(t + 1) / block - 1] = rows[cur].v;
    cur = 1 - cur;
  }
  result.total_cost = offset + rows[1 - cur].min;
  result.forward_seconds = Seconds(start) - cost_seconds_;
  const double forward_cost_seconds = cost_seconds_;

  // Backward: recompute each block from its checkpoint, keeping M rows and record bytes,
  // then walk the path back through it.
  const auto back_start = std::chrono::steady_clock::now();
  // M rows of the block, each padded like Row::m_storage: the steps write into them directly.
  const size_t m_stride = stride_ + 2 * static_cast<size_t>(pad_);
  std::vector<float> block_m(static_cast<size_t>(block + 1) * m_stride, kInf);
  const auto m_row = [&](size_t i) { return block_m.data() + i * m_stride + pad_; };
  std::vector<uint8_t> block_rec(static_cast<size_t>(block + 1) * S_);
  std::vector<std::vector<TopEntry>> block_top(block + 1);
  result.source_frames.assign(T_, 0);
  int s = -1, r = 0;
  tile_first_ = -1;
  tile_count_ = 0;
  for (int b = blocks - 1; b >= 0; --b) {
    const int b0 = b * block, b1 = std::min(T_, b0 + block);
    // Local row i holds target row b0 - 1 + i.
    cur = 0;
    if (b > 0) {
      rows[cur].m = m_row(0);
      StateFromCheckpoint(checkpoints[b - 1], &rows[cur], block_rec.data());
      Finish(&rows[cur], b0 - 1);
      block_top[0] = rows[cur].top;
      checkpoints[b - 1] = {};
      cur = 1;
    }
    for (int t = b0; t < b1; ++t) {
      const float* c = CostRow(t, b1);
      const size_t i = t - b0 + 1;
      uint8_t* record = block_rec.data() + i * S_;
      rows[cur].m = m_row(i);
      if (t == 0) {
        Init(c, &rows[cur], record);
      } else {
        Step(t, c, rows[1 - cur], &rows[cur], record);
      }
      block_top[i] = rows[cur].top;
      cur = 1 - cur;
    }
    if (s < 0) {  // the last row: its best state
      const size_t i = b1 - b0;
      const float* m = m_row(i);
      s = static_cast<int>(std::min_element(m, m + S_) - m);
      r = block_rec[i * S_ + s] & 7;
    }
    for (int t = b1 - 1; t >= b0; --t) {
      result.source_frames[t] = s;
      if (t == 0) break;
      const size_t i = t - b0 + 1;
      std::tie(s, r) = Predecessor(t, s, r, m_row(i - 1), block_rec.data() + (i - 1) * S_,
                                   block_rec.data() + i * S_, block_top[i - 1]);
    }
  }
  result.cost_seconds = cost_seconds_;
  result.backward_seconds = Seconds(back_start) - (cost_seconds_ - forward_cost_seconds);
  result.memory_bytes = static_cast<size_t>(blocks - 1) * (R_ + 1) * stride_ * sizeof(float) +
                        block_m.size() * sizeof(float) + block_rec.size();
}

}  // namespace

MatchResult SolveMatch(const CostRows& costs, const std::vector<int>& clip_starts,
                       const MatchOptions& options, const MovementConstraint* movements) {
  Engine engine(costs, clip_starts, options, movements);
  MatchResult result = engine.Solve();
  if (!result.source_frames.empty()) {
    double matching = 0;
    PathCost(costs, clip_starts, options, movements, result.source_frames, &matching);
    result.matching_cost = matching;
    result.stats = AnalyzePath(result.source_frames, clip_starts, options);
  }
  Log("animate.match")->debug("{}", result.Summary());
  return result;
}

namespace {

// The cost of move s' -> s at a free row, by the rules (listed transitions aside).
double RuleCost(int from, int to, const std::vector<int>& clip, const MatchOptions& o) {
  const int d = to - from;
  if (clip[from] == clip[to] && d >= 1 && d <= o.max_forward_step)
    return o.skip_cost * static_cast<double>(d - 1);
  if (clip[from] == clip[to] && d < 0 && -d <= o.stutter_window) {
    return static_cast<double>(o.jump_cost) + o.stutter_cost;
  }
  return o.jump_cost;
}

double ListedCost(int from, int to, const MatchOptions& o) {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& tr : o.transitions) {
    if (tr.from == from && tr.to == to && tr.from != tr.to) best = std::min<double>(best, tr.cost);
  }
  return best;
}

}  // namespace

double PathCost(const CostRows& costs, const std::vector<int>& clip_starts,
                const MatchOptions& options, const MovementConstraint* movements,
                const std::vector<int>& path, double* matching_cost) {
  const double inf = std::numeric_limits<double>::infinity();
  const int T = costs.targets(), S = costs.sources();
  if (static_cast<int>(path.size()) != T)
    throw InputError("path", "needs one source frame per target frame");
  const std::vector<int> clip = SegmentIds(clip_starts, S);
  std::vector<int> movement;
  std::vector<uint8_t> inside(T, 0);
  if (movements) {
    movement = SegmentIds(movements->source_starts, S);
    std::fill(inside.begin(), inside.end(), 1);
    for (int t : movements->target_starts) inside[t] = 0;
    if (T > 0) inside[0] = 0;
  }
  double match = 0, total = 0;
  int run = 0;
  for (int t = 0; t < T; ++t) {
    const int s = path[t];
    if (s < 0 || s >= S)
      throw InputError("path", "source frame " + std::to_string(s) + " out of range");
    match += costs.At(t, s);
    if (t == 0) continue;
    const int from = path[t - 1];
    if (s == from) {
      ++run;
      total += options.freeze_cost * static_cast<double>(std::min(run, options.freeze_levels));
      continue;
    }
    run = 0;
    if (inside[t] && movement[from] != movement[s]) {
      total = inf;
      continue;
    }
    double move = RuleCost(from, s, clip, options);
    const int d = s - from;
    if (inside[t] && !(d >= 1 && d <= options.max_forward_step)) {
      move += static_cast<double>(movements->jump_cost_per_frame) * std::abs(d);
    }
    total += std::min(move, ListedCost(from, s, options));
  }
  if (matching_cost) *matching_cost = match;
  return total + match;
}

MatchStats AnalyzePath(const std::vector<int>& path, const std::vector<int>& clip_starts,
                       const MatchOptions& options) {
  MatchStats stats;
  if (path.empty()) return stats;
  const int S = *std::max_element(path.begin(), path.end()) + 1;
  std::vector<int> starts;
  for (int c : clip_starts) {
    if (c < S) starts.push_back(c);
  }
  const std::vector<int> clip = SegmentIds(starts.empty() ? std::vector<int>{0} : starts, S);
  int run = 0;
  for (size_t t = 1; t < path.size(); ++t) {
    const int from = path[t - 1], to = path[t];
    if (to == from) {
      if (run == 0) ++stats.freeze_runs;
      ++run;
      ++stats.freezes;
      stats.longest_freeze = std::max(stats.longest_freeze, run);
      continue;
    }
    run = 0;
    const double rule = RuleCost(from, to, clip, options);
    if (ListedCost(from, to, options) < rule) {
      ++stats.listed;
      continue;
    }
    const int d = to - from;
    if (clip[from] == clip[to] && d >= 1 && d <= options.max_forward_step) {
      if (d >= 2) ++stats.skips;
    } else if (clip[from] == clip[to] && d < 0 && -d <= options.stutter_window) {
      ++stats.stutters;
    } else {
      ++stats.jumps;
    }
  }
  return stats;
}

}  // namespace ss
