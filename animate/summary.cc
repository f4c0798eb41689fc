#include "animate/summary.h"

#include <chrono>
#include <cstdio>

namespace ss {

const char* TerminationTypeName(TerminationType type) {
  switch (type) {
    case TerminationType::kConverged:
      return "CONVERGED";
    case TerminationType::kTimeBudget:
      return "TIME_BUDGET";
    case TerminationType::kMaxTurns:
      return "MAX_TURNS";
    case TerminationType::kBeamComplete:
      return "BEAM_COMPLETE";
    case TerminationType::kCancelled:
      return "CANCELLED";
  }
  return "UNKNOWN";
}

std::string Summary::BriefReport() const {
  char line[256];
  std::snprintf(line, sizeof line,
                "%s (start %s): cost %.6g -> %.6g, %lld/%lld moves kept, %d turns, %d restarts, "
                "%.2f s, %s",
                method.c_str(), start.c_str(), initial_cost.total, final_cost.total,
                static_cast<long long>(moves_kept), static_cast<long long>(moves_tried), turns,
                restarts, total_seconds, TerminationTypeName(termination));
  return line;
}

std::string Summary::FullReport() const {
  std::string out;
  char line[256];
  auto add = [&](const char* format, auto... args) {
    std::snprintf(line, sizeof line, format, args...);
    out += line;
  };
  add("Animation optimization report\n");
  add("  method             %s (start: %s)\n", method.c_str(), start.c_str());
  add("  sprites            %d\n", num_sprites);
  add("  turns              %d\n", turns);
  add("  restarts           %d\n", restarts);
  add("  picks              %lld (%lld at a collision, %lld toward a frame set)\n",
      static_cast<long long>(picks), static_cast<long long>(collision_picks),
      static_cast<long long>(goal_picks));
  add("  moves tried/kept   %lld / %lld\n", static_cast<long long>(moves_tried),
      static_cast<long long>(moves_kept));
  add("  time precompute    %.3f s\n", precompute_seconds);
  add("  time start         %.3f s\n", start_seconds);
  add("  time optimize      %.3f s\n", optimize_seconds);
  add("  time total         %.3f s\n", total_seconds);
  add("  %-18s %14s %14s %10s\n", "cost", "initial", "final", "violations");
  add("  %-18s %14.6g %14.6g\n", "total", initial_cost.total, final_cost.total);
  for (const auto& [kind, value] : final_cost.by_kind) {
    const auto initial = initial_cost.by_kind.find(kind);
    const auto violations = final_cost.violations.find(kind);
    add("  %-18s %14.6g %14.6g %10d\n", kind.c_str(),
        initial == initial_cost.by_kind.end() ? 0.0 : initial->second, value,
        violations == final_cost.violations.end() ? 0 : violations->second);
  }
  add("  termination        %s: %s\n", TerminationTypeName(termination), message.c_str());
  return out;
}

namespace {
int64_t NowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}
}  // namespace

ScopedTimer::ScopedTimer(double* seconds) : seconds_(seconds), start_ns_(NowNs()) {}

ScopedTimer::~ScopedTimer() { *seconds_ += static_cast<double>(NowNs() - start_ns_) * 1e-9; }

}  // namespace ss
