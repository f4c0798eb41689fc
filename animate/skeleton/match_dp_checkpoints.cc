// SolveMatch's second backtrack strategy (match_dp.h), for when the decisions would not fit
// MatchOptions::max_decision_bytes: memory O(S sqrt(T)); rows are checkpointed on the forward
// pass and recomputed block by block for the backtrack.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <tuple>

#include "animate/skeleton/match_dp_detail.h"
#include "core/error.h"

namespace ss::match_dp_detail {

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
  RowPair rows(R_, stride_, pad_);
  for (int t = 0; t < T_; ++t) {
    Forward(t, CostRow(t, T_), &rows, nullptr);
    if ((t + 1) % block == 0 && (t + 1) / block < blocks)
      checkpoints[(t + 1) / block - 1] = rows.Now().v;
    rows.Next();
  }
  result.total_cost = rows.Total();
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
    // (rows.offset sums on here too, unused: the total is known)
    rows.cur = 0;
    if (b > 0) {
      rows.Now().m = m_row(0);
      StateFromCheckpoint(checkpoints[b - 1], &rows.Now(), block_rec.data());
      Finish(&rows.Now(), b0 - 1);
      block_top[0] = rows.Now().top;
      checkpoints[b - 1] = {};
      rows.Next();
    }
    for (int t = b0; t < b1; ++t) {
      const size_t i = t - b0 + 1;
      rows.Now().m = m_row(i);
      Forward(t, CostRow(t, b1), &rows, block_rec.data() + i * S_);
      block_top[i] = rows.Now().top;
      rows.Next();
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

}  // namespace ss::match_dp_detail
