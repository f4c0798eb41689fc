#include "pipeline/transitions/truth_labels.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <random>
#include <set>
#include <unordered_map>

#include "core/error.h"
#include "core/option_checks.h"

namespace ss {

double HeadingDifference(double a, double b) {
  double d = std::fmod(std::abs(a - b), 2.0 * M_PI);
  return d > M_PI ? 2.0 * M_PI - d : d;
}

double PhaseDifference(double a, double b) {
  double d = std::fmod(std::abs(a - b), 1.0);
  return d > 0.5 ? 1.0 - d : d;
}

double KeypointDisplacement(const SpriteTruth& a, const SpriteTruth& b) {
  if (a.keypoints_m.empty() || a.keypoints_m.size() != b.keypoints_m.size() ||
      a.keypoints_m.size() % 2 != 0 || a.unordered_from != b.unordered_from) {
    return INFINITY;
  }
  const size_t points = a.keypoints_m.size() / 2;
  const auto& va = a.keypoint_visible;
  const auto& vb = b.keypoint_visible;
  if ((!va.empty() && va.size() != points) || (!vb.empty() && vb.size() != points)) return INFINITY;
  const bool flags = !va.empty() && !vb.empty();
  // Point k of a against point l of b: compared when visible in at least one.
  const auto seen = [&](size_t k, size_t l) { return !flags || va[k] || vb[l]; };
  const auto distance = [&](size_t k, size_t l) {
    return std::hypot(a.keypoints_m[2 * k] - b.keypoints_m[2 * l],
                      a.keypoints_m[2 * k + 1] - b.keypoints_m[2 * l + 1]);
  };
  const size_t fixed =
      a.unordered_from < 0 ? points : std::min(points, static_cast<size_t>(a.unordered_from));
  double worst = 0;
  for (size_t k = 0; k < fixed; ++k) {
    if (seen(k, k)) worst = std::max(worst, distance(k, k));
  }
  const size_t feet = points - fixed;
  if (feet == 0) return worst;
  if (feet > 8) return INFINITY;  // 8! matchings at most; no truth has more feet
  // Bottleneck matching by enumeration (4 feet: 24 matchings) on the pairwise distances.
  std::array<double, 64> cost{};
  for (size_t k = 0; k < feet; ++k) {
    for (size_t l = 0; l < feet; ++l)
      cost[k * feet + l] = seen(fixed + k, fixed + l) ? distance(fixed + k, fixed + l) : 0.0;
  }
  std::array<int, 8> perm{};
  std::iota(perm.begin(), perm.begin() + feet, 0);
  double best = INFINITY;
  do {
    double w = 0;
    for (size_t k = 0; k < feet && w < best; ++k) w = std::max(w, cost[k * feet + perm[k]]);
    best = std::min(best, w);
  } while (best > 0 && std::next_permutation(perm.begin(), perm.begin() + feet));
  return std::max(worst, best);
}

namespace {

bool Within(const SpriteTruth& a, const SpriteTruth& b, const TruthLabelOptions& o, double factor) {
  if (a.pose != b.pose) return false;
  if (!a.keypoints_m.empty() && !b.keypoints_m.empty()) {
    return KeypointDisplacement(a, b) <= factor * o.max_keypoint_displacement_m;
  }
  if (HeadingDifference(a.heading_rad, b.heading_rad) > factor * o.max_heading_difference_rad)
    return false;
  const bool a_gait = !std::isnan(a.gait_phase), b_gait = !std::isnan(b.gait_phase);
  if (a_gait != b_gait) return false;
  return !a_gait || PhaseDifference(a.gait_phase, b.gait_phase) <= factor * o.max_phase_difference;
}

}  // namespace

bool TruthLabelOptions::IsValid(std::string* why) const {
  OptionProblems check(why);
  for (const auto& [v, field] :
       {std::pair{max_heading_difference_rad, "max_heading_difference_rad"},
        std::pair{max_phase_difference, "max_phase_difference"},
        std::pair{max_keypoint_displacement_m, "max_keypoint_displacement_m"}}) {
    check(std::isfinite(v) && v >= 0, field,
          "expected a number >= 0, got " + OptionProblems::Num(v));
  }
  check.Within(near_miss_fraction, Between(0, 1), "near_miss_fraction", "a share from 0 to 1");
  // Below 1 a near miss would have to be nearer than an accept.
  check.Within(near_miss_factor, AtLeast(1), "near_miss_factor", "a factor >= 1");
  return check.ok();
}

bool TruthAccepts(const SpriteTruth& a, const SpriteTruth& b, const TruthLabelOptions& options) {
  return Within(a, b, options, 1.0);
}

double TruthPositiveRate(std::span<const SpriteTruth> truth, const TruthLabelOptions& options,
                         int rows, uint64_t seed) {
  if (std::string why; !options.IsValid(&why)) throw InputError("truth label options", why);
  const size_t n = truth.size();
  if (n < 2) return 0.0;
  std::vector<size_t> sample(n);
  std::iota(sample.begin(), sample.end(), size_t{0});
  if (rows > 0 && static_cast<size_t>(rows) < n) {
    std::mt19937_64 rng(seed);
    std::shuffle(sample.begin(), sample.end(), rng);
    sample.resize(static_cast<size_t>(rows));
  }
  double positives = 0;
  for (size_t i : sample) {
    for (size_t j = 0; j < n; ++j) positives += j != i && TruthAccepts(truth[i], truth[j], options);
  }
  return positives / (static_cast<double>(sample.size()) * static_cast<double>(n - 1));
}

std::vector<Label> LabelsFromTruth(std::span<const int64_t> ids, std::span<const SpriteTruth> truth,
                                   size_t count, const TruthLabelOptions& options, uint64_t seed) {
  if (std::string why; !options.IsValid(&why)) throw InputError("truth label options", why);
  const size_t n = truth.size();
  if (ids.size() != n) throw WorkError("LabelsFromTruth: ids and truth disagree");
  if (n < 2) throw InputError("truth", "at least two sprites are needed to make labels");
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<size_t> pick(0, n - 1);
  std::set<std::pair<size_t, size_t>> used;
  std::vector<Label> labels;
  auto add = [&](size_t i, size_t j, bool accept) {
    if (i == j || !used.emplace(std::min(i, j), std::max(i, j)).second) return false;
    labels.push_back({ids[i], ids[j], accept});
    return true;
  };
  const size_t want_accepts = count / 2,
               want_near = static_cast<size_t>((count - want_accepts) * options.near_miss_fraction);
  // Accepts and near misses: scan all partners of random sprites.
  size_t accepts = 0, near = 0;
  std::vector<size_t> partners, misses;
  for (size_t attempt = 0; attempt < 20 * count && (accepts < want_accepts || near < want_near);
       ++attempt) {
    const size_t i = pick(rng);
    partners.clear();
    misses.clear();
    for (size_t j = 0; j < n; ++j) {
      if (j == i) continue;
      if (TruthAccepts(truth[i], truth[j], options)) {
        partners.push_back(j);
      } else if (Within(truth[i], truth[j], options, options.near_miss_factor)) {
        misses.push_back(j);
      }
    }
    if (accepts < want_accepts && !partners.empty()) {
      accepts += add(
          i, partners[std::uniform_int_distribution<size_t>(0, partners.size() - 1)(rng)], true);
    }
    if (near < want_near && !misses.empty()) {
      near +=
          add(i, misses[std::uniform_int_distribution<size_t>(0, misses.size() - 1)(rng)], false);
    }
  }
  // Uniform random rejects for the rest.
  for (size_t attempt = 0; attempt < 20 * count && labels.size() < accepts + (count - want_accepts);
       ++attempt) {
    const size_t i = pick(rng), j = pick(rng);
    if (!TruthAccepts(truth[i], truth[j], options)) add(i, j, false);
  }
  return labels;
}

}  // namespace ss
