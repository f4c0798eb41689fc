#include "animate/cost_term.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"

namespace ss {

std::pair<int, int> StepWindow::Resolve(int n) const {
  const int begin = std::max(0, first_from_end ? n - 1 - first : first);
  const int end = (last_from_end ? n - 1 - last : last) + 1;
  return {begin, std::max(begin, end)};
}

CostTerm::CostTerm(std::string kind, std::vector<int> sprites, double strength)
    : kind_(std::move(kind)), sprites_(std::move(sprites)), strength_(strength) {
  if (!std::isfinite(strength) || strength < 0) {
    throw InputError(kind_ + ".strength",
                     "must be finite and >= 0, got " + std::to_string(strength));
  }
}

int StepSumTerm::MaxLength(Tracks tracks) const {
  int n = 0;
  for (int s : sprites()) n = std::max(n, tracks[s]->size());
  return n;
}

double StepSumTerm::Evaluate(Tracks tracks, const EvalRequest& request) const {
  auto [begin, end] = Steps(tracks, request);
  end = std::min(end, request.step_limit);
  double sum = request.partial() ? 0.0 : EndCost(tracks);
  if (end <= begin || sum > request.budget) return sum;
  int from = begin;
  int to = end;  // steps [from, to) are computed
  if (request.cache != nullptr && !request.cache->prefix.empty()) {
    const std::vector<double>& prefix = request.cache->prefix;
    const int cached_size = static_cast<int>(prefix.size()) - 1;
    const int unchanged = FramesOnly() && request.first_frame_changed >= 0
                              ? request.first_frame_changed
                              : request.first_changed;
    const int cached_end = std::min({unchanged, cached_size, end});
    if (cached_end > begin) {
      sum += prefix[cached_end] - prefix[begin];
      from = cached_end;
    }
    if (TimeInvariant() && request.shifted_from < end) {
      // Steps t >= shifted_from + LookBack() read frames of the shifted part only (both of
      // their edge's), as their old steps t - shift did (frame shifted_from was old frame
      // shifted_from - shift >= 0, so no old window was cut by step 0).
      const int shifted_begin = std::max(from, request.shifted_from + LookBack());
      const int old_begin = shifted_begin - request.shift;
      const int old_end = end - request.shift;
      if (old_begin >= 0 && old_end <= cached_size && old_begin <= old_end) {
        sum += prefix[old_end] - prefix[old_begin];
        to = shifted_begin;
      }
    }
  }
  if (sum > request.budget) return sum;
  for (int t = from; t < to; ++t) {
    sum += StepCost(tracks, t);
    if (sum > request.budget) return sum;
  }
  return sum;
}

void StepSumTerm::BuildCache(Tracks tracks, TermCache* cache) const {
  const int horizon = std::max(Steps(tracks, EvalRequest{}).second, MaxLength(tracks));
  cache->prefix.assign(horizon + 1, 0.0);
  for (int t = 0; t < horizon; ++t) cache->prefix[t + 1] = cache->prefix[t] + StepCost(tracks, t);
}

}  // namespace ss
