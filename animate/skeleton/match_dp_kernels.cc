// The forward pass's row step of SolveMatch (match_dp.h): the vectorized kernel over a row,
// the scalar cell update for tails and fix-ups, local jumps and each row's top list.
#include <algorithm>
#include <cstring>

#include "animate/skeleton/match_dp_detail.h"
#include "core/error.h"
#include "core/float8.h"
#include "core/target_clones.h"

// GCC notes that 32-byte vector arguments change the ABI without AVX; these helpers are
// inline and never cross a library boundary.
#pragma GCC diagnostic ignored "-Wpsabi"

namespace ss::match_dp_detail {

using float8::Load;
using float8::Store;
using float8::v8f;
typedef int v8i __attribute__((vector_size(32)));
typedef uint8_t v8u8 __attribute__((vector_size(8)));
typedef uint16_t v8u16 __attribute__((vector_size(16)));

inline v8f Min(v8f a, v8f b) { return a < b ? a : b; }

namespace {

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

SS_TARGET_CLONES("arch=x86-64-v4", "arch=x86-64-v3", "default")
void StepKernel(const StepArgs& args) {
  if (args.masked) {
    StepModes<true>(args);
  } else {
    StepModes<false>(args);
  }
}

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

void Engine::Forward(int t, const float* c, RowPair* rows, uint8_t* record, int32_t* jump_source) {
  if (t == 0) {
    Init(c, &rows->Now(), record);
    return;
  }
  rows->offset += rows->Before().min;
  Step(t, c, rows->Before(), &rows->Now(), record, jump_source);
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

}  // namespace ss::match_dp_detail
