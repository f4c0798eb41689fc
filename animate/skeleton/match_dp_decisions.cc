// SolveMatch's first backtrack strategy (match_dp.h): the forward pass stores every cell's
// decision, and the backtrack walks them. Engine::Solve falls back to the checkpoints
// (match_dp_checkpoints.cc) when they would not fit the budget.
#include <algorithm>
#include <chrono>
#include <cstddef>
#include <fstream>
#include <limits>
#include <memory>

#include <sys/mman.h>

#include "animate/skeleton/match_dp_detail.h"
#include "core/error.h"
#include "core/log.h"

namespace ss::match_dp_detail {

namespace {

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

}  // namespace

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
  RowPair rows(R_, stride_, pad_);
  for (int t = 0; t < T_; ++t) {
    listed_begin[t] = listed_choice_.size();
    Forward(t, CostRow(t, T_), &rows, decisions.get() + static_cast<size_t>(t) * row_bytes,
            local_row[t] >= 0 ? jump_sources + static_cast<size_t>(local_row[t]) * S_ : nullptr);
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
    const auto& top = rows.Now().top;
    for (size_t i = 0; i < top.size() && i < top_size; ++i) tops[t * top_size + i] = top[i].index;
    rows.Next();
  }
  listed_begin[T_] = listed_choice_.size();
  result.total_cost = rows.Total();
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
  const float* m_last = rows.Before().m;
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

}  // namespace ss::match_dp_detail
