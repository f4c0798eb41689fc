#pragma once
// The inside of SolveMatch (match_dp.h), shared by its parts and used only inside
// animate/skeleton/:
//   match_dp.cc              the driver: options, row rules, the Engine's set-up, SolveMatch
//   match_dp_kernels.cc      the forward pass's row step: the vectorized kernel, the scalar
//                            cells and fix-ups, local jumps, each row's top list
//   match_dp_decisions.cc    backtrack 1: walk the decisions the forward pass stored
//   match_dp_checkpoints.cc  backtrack 2: recompute blocks of rows from checkpoints
//   match_path_cost.cc       PathCost and AnalyzePath, the reference straight from the
//                            definition
#include <algorithm>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "animate/skeleton/cost_rows.h"
#include "animate/skeleton/match_dp.h"

namespace ss::match_dp_detail {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr int kLanes = 8;
constexpr int kCostTile = 16;  // target rows of costs computed at once

// What a step records per cell. The low byte always holds argmin_r V(s, r) (bits 0-2) and
// whether V(s, R) came from r = R-1 (bit 3). kPacked adds the move into (s, 0) in bits
// 4-7; kWide stores 2 bytes a cell, the move in the second. Move codes: 0 none (V(s,0) is
// +inf), k = 1..Kf advance by k, Kf + k (k = 1..W) stutter back by k, Kf + W + 1 a jump
// (global: the first entry of the previous row's top list outside [s, s+W]; local: the
// row's stored jump source). A listed transition that wins is kept aside per row.
enum RecordMode { kArgOnly = 1, kPacked = 2, kWide = 3 };

inline float Min(float a, float b) { return a < b ? a : b; }

// Checks the clip (or movement) starts of `count` frames.
void CheckStarts(const std::vector<int>& starts, int count, const std::string& what);

// Segment id of every frame.
std::vector<int> SegmentIds(const std::vector<int>& starts, int count);

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

RowRules MakeRules(const std::vector<int>& starts, int count, const MatchOptions& o, bool local);

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

// The forward pass's two rows, used in turn: Now() is row t's, Before() row t-1's; `offset`
// sums the row minima subtracted on the way (Engine::Forward adds them).
struct RowPair {
  RowPair(int levels, size_t stride, int pad) {
    for (auto& r : rows) r.Allocate(levels, stride, pad);
  }
  Row& Now() { return rows[cur]; }
  Row& Before() { return rows[1 - cur]; }
  void Next() { cur = 1 - cur; }
  // After the last row's Next(): the path's cost, offset and that row's minimum.
  double Total() const { return offset + rows[1 - cur].min; }

  Row rows[2];
  int cur = 0;
  double offset = 0;
};

inline double Seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

// The solver. Its members are defined by part: the set-up and Solve in match_dp.cc, the row
// step in match_dp_kernels.cc, the backtracks in match_dp_decisions.cc and
// match_dp_checkpoints.cc.
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
  // Row t into rows->Now(): Init for the first row, else Step from rows->Before(), whose
  // minimum goes to rows->offset.
  void Forward(int t, const float* c, RowPair* rows, uint8_t* record,
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

}  // namespace ss::match_dp_detail
