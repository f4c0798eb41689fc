#include "pipeline/transitions/training.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <mutex>
#include <numeric>
#include <random>
#include <sstream>
#include <thread>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/option_checks.h"

namespace ss {

// ---- labels file ----

std::vector<Label> ReadLabelsCsv(const std::string& path, double* positive_rate) {
  if (positive_rate) *positive_rate = -1;
  std::ifstream in(path);
  if (!in) throw InputError(path, "cannot open the labels file");
  std::string line;
  int line_number = 0;
  std::vector<Label> labels;
  bool header_seen = false;
  while (std::getline(in, line)) {
    ++line_number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const std::string where = path + ":" + std::to_string(line_number);
    if (!line.empty() && line[0] == '#') {
      const std::string key = "# positive_rate=";
      if (line.rfind(key, 0) == 0) {
        try {
          size_t used = 0;
          const double rate = std::stod(line.substr(key.size()), &used);
          if (used != line.size() - key.size() || !(rate > 0 && rate < 1))
            throw std::invalid_argument("range");
          if (positive_rate) *positive_rate = rate;
        } catch (const std::exception&) {
          throw InputError(where, "positive_rate must be a number in (0, 1): '" + line + "'");
        }
      }
      continue;
    }
    if (line.empty()) continue;
    if (!header_seen) {
      if (line != "sprite_i,sprite_j,accept") {
        throw InputError(where,
                         "expected the header 'sprite_i,sprite_j,accept', got '" + line + "'");
      }
      header_seen = true;
      continue;
    }
    std::stringstream ss(line);
    std::string fields[3], extra;
    for (auto& f : fields) {
      if (!std::getline(ss, f, ','))
        throw InputError(where, "expected 3 comma-separated fields: '" + line + "'");
    }
    if (std::getline(ss, extra, ',')) throw InputError(where, "more than 3 fields: '" + line + "'");
    Label label;
    try {
      size_t used = 0;
      label.sprite_i = std::stoll(fields[0], &used);
      if (used != fields[0].size()) throw std::invalid_argument("trailing");
      label.sprite_j = std::stoll(fields[1], &used);
      if (used != fields[1].size()) throw std::invalid_argument("trailing");
    } catch (const std::exception&) {
      throw InputError(where, "sprite ids must be integers: '" + line + "'");
    }
    if (fields[2] == "1") {
      label.accept = true;
    } else if (fields[2] == "0") {
      label.accept = false;
    } else {
      throw InputError(where, "accept must be 1 or 0, got '" + fields[2] + "'");
    }
    if (label.sprite_i == label.sprite_j) throw InputError(where, "a sprite paired with itself");
    labels.push_back(label);
  }
  if (!header_seen) throw InputError(path, "empty: expected the header 'sprite_i,sprite_j,accept'");
  return labels;
}

void WriteLabelsCsv(const std::vector<Label>& labels, const std::string& path,
                    double positive_rate) {
  std::ofstream out(path, std::ios::trunc);
  if (!out) throw WorkError(path, "cannot open for writing");
  if (positive_rate >= 0) {
    char text[64];
    std::snprintf(text, sizeof(text), "# positive_rate=%.9g\n", positive_rate);
    out << text;
  }
  out << "sprite_i,sprite_j,accept\n";
  for (const Label& l : labels)
    out << l.sprite_i << ',' << l.sprite_j << ',' << (l.accept ? 1 : 0) << '\n';
  out.close();
  if (!out) throw WorkError(path, "write failed");
}

// ---- logistic regression ----

namespace {

double Softplus(double s) { return s > 0 ? s + std::log1p(std::exp(-s)) : std::log1p(std::exp(s)); }
double Sigmoid(double s) {
  return s >= 0 ? 1.0 / (1.0 + std::exp(-s)) : std::exp(s) / (1.0 + std::exp(s));
}

struct Problem {
  std::span<const double> z;
  int dims;
  std::vector<double> reject;  // 1 = reject, 0 = accept
  std::vector<double> weight;  // per sample, sums to 1
  double l2;

  // Loss and gradient at theta = (w, b).
  double Evaluate(const std::vector<double>& theta, std::vector<double>* gradient) const {
    const size_t n = reject.size();
    gradient->assign(dims + 1, 0.0);
    double loss = 0;
    for (size_t i = 0; i < n; ++i) {
      const double* row = &z[i * dims];
      double s = theta[dims];
      for (int k = 0; k < dims; ++k) s += theta[k] * row[k];
      loss += weight[i] * (Softplus(s) - reject[i] * s);
      const double g = weight[i] * (Sigmoid(s) - reject[i]);
      for (int k = 0; k < dims; ++k) (*gradient)[k] += g * row[k];
      (*gradient)[dims] += g;
    }
    for (int k = 0; k < dims; ++k) {
      loss += 0.5 * l2 * theta[k] * theta[k];
      (*gradient)[k] += l2 * theta[k];
    }
    return loss;
  }

  // A Lipschitz constant of the gradient: 0.25 * largest eigenvalue of sum w x x^T (+ l2).
  double Lipschitz() const {
    const int d = dims + 1;
    std::vector<double> m(d * d, 0.0);
    for (size_t i = 0; i < reject.size(); ++i) {
      const double* row = &z[i * dims];
      for (int a = 0; a < d; ++a) {
        const double xa = a < dims ? row[a] : 1.0;
        for (int b = 0; b < d; ++b) m[a * d + b] += weight[i] * xa * (b < dims ? row[b] : 1.0);
      }
    }
    std::vector<double> v(d, 1.0), next(d);
    double lambda = 0;
    for (int it = 0; it < 100; ++it) {
      for (int a = 0; a < d; ++a) {
        next[a] = 0;
        for (int b = 0; b < d; ++b) next[a] += m[a * d + b] * v[b];
      }
      const double norm =
          std::sqrt(std::inner_product(next.begin(), next.end(), next.begin(), 0.0));
      if (norm == 0) break;
      lambda = norm;
      for (int a = 0; a < d; ++a) v[a] = next[a] / norm;
    }
    return 0.25 * lambda * 1.01 + l2 + 1e-12;
  }
};

}  // namespace

bool LogisticOptions::IsValid(std::string* why) const {
  OptionProblems check(why);
  check(std::isfinite(l2) && l2 >= 0, "l2",
        "expected a number >= 0, got " + OptionProblems::Num(l2));
  check.Within(max_iterations, AtLeast(1), "max_iterations", "at least 1");
  check.Within(tolerance, AtLeast(0), "tolerance", "a number >= 0");
  return check.ok();
}

LinearModel FitLogistic(std::span<const double> z, int dims, std::span<const uint8_t> accept,
                        const LogisticOptions& options) {
  const size_t n = accept.size();
  if (std::string why; !options.IsValid(&why)) throw InputError("logistic options", why);
  if (z.size() != n * dims) throw WorkError("FitLogistic: feature rows and labels disagree");
  Problem p{z, dims, std::vector<double>(n), std::vector<double>(n), options.l2};
  size_t accepts = 0;
  for (size_t i = 0; i < n; ++i) accepts += accept[i] ? 1 : 0;
  for (size_t i = 0; i < n; ++i) {
    p.reject[i] = accept[i] ? 0.0 : 1.0;
    if (options.balance_classes && accepts > 0 && accepts < n) {
      p.weight[i] = 0.5 / static_cast<double>(accept[i] ? accepts : n - accepts);
    } else {
      p.weight[i] = 1.0 / static_cast<double>(n);
    }
  }
  const double step = 1.0 / p.Lipschitz();
  auto project = [&](std::vector<double>& theta) {
    if (options.non_negative) {
      for (int k = 0; k < dims; ++k) theta[k] = std::max(0.0, theta[k]);
    }
  };
  // FISTA with adaptive restart.
  std::vector<double> x(dims + 1, 0.0), y = x, x_prev = x, gradient;
  double t = 1.0, loss = p.Evaluate(x, &gradient), previous_loss = loss;
  LinearModel model;
  int stalls = 0;
  for (int it = 1; it <= options.max_iterations; ++it) {
    p.Evaluate(y, &gradient);
    x_prev = x;
    for (int k = 0; k <= dims; ++k) x[k] = y[k] - step * gradient[k];
    project(x);
    loss = p.Evaluate(x, &gradient);
    model.iterations = it;
    if (loss > previous_loss) {  // restart the momentum
      t = 1.0;
      y = x;
    } else {
      const double t_next = 0.5 * (1.0 + std::sqrt(1.0 + 4.0 * t * t));
      for (int k = 0; k <= dims; ++k) y[k] = x[k] + (t - 1.0) / t_next * (x[k] - x_prev[k]);
      t = t_next;
    }
    const bool small =
        std::abs(previous_loss - loss) <= options.tolerance * std::max(1.0, std::abs(loss));
    stalls = small ? stalls + 1 : 0;
    previous_loss = loss;
    if (stalls >= 20) break;
  }
  model.weights.assign(x.begin(), x.begin() + dims);
  model.bias = x[dims];
  model.loss = loss;
  return model;
}

// ---- training both stages ----

double Confusion::precision() const {
  const int64_t accepted = true_accept + false_accept;
  return accepted > 0 ? static_cast<double>(true_accept) / accepted : 0.0;
}
double Confusion::recall() const {
  const int64_t positives = true_accept + false_reject;
  return positives > 0 ? static_cast<double>(true_accept) / positives : 0.0;
}

std::string TrainReport::ToJson() const {
  auto confusion = [](const Confusion& c) {
    return nlohmann::json{{"precision", c.precision()},   {"recall", c.recall()},
                          {"true_accept", c.true_accept}, {"false_accept", c.false_accept},
                          {"true_reject", c.true_reject}, {"false_reject", c.false_reject}};
  };
  nlohmann::json j{{"samples", samples},
                   {"accepts", accepts},
                   {"cross_validation_folds", folds},
                   {"stage1_cross_validated", confusion(stage1)},
                   {"stage2_cross_validated", confusion(stage2)}};
  return j.dump();
}

namespace {

struct Standardization {
  PairFeatures mean{}, scale{};
};
Standardization Standardize(std::span<const PairFeatures> x, std::span<const size_t> rows) {
  Standardization s;
  for (int k = 0; k < kPairFeatureCount; ++k) {
    double sum = 0, sum_sq = 0;
    for (size_t r : rows) {
      sum += x[r][k];
      sum_sq += x[r][k] * x[r][k];
    }
    const double n = static_cast<double>(rows.size());
    s.mean[k] = sum / n;
    const double var = std::max(0.0, sum_sq / n - s.mean[k] * s.mean[k]);
    s.scale[k] = var > 1e-24 ? std::sqrt(var) : 1.0;
  }
  return s;
}

// Fits one stage on the first `dims` features of `rows`.
LinearModel FitStage(std::span<const PairFeatures> x, std::span<const uint8_t> accept,
                     std::span<const size_t> rows, const Standardization& s, int dims,
                     const LogisticOptions& options) {
  std::vector<double> z(rows.size() * dims);
  std::vector<uint8_t> y(rows.size());
  for (size_t r = 0; r < rows.size(); ++r) {
    for (int k = 0; k < dims; ++k) z[r * dims + k] = (x[rows[r]][k] - s.mean[k]) / s.scale[k];
    y[r] = accept[rows[r]];
  }
  return FitLogistic(z, dims, y, options);
}

bool Predicts(const LinearModel& m, const Standardization& s, const PairFeatures& x, int dims) {
  double v = m.bias;
  for (int k = 0; k < dims; ++k) v += m.weights[k] * (x[k] - s.mean[k]) / s.scale[k];
  return v <= 0;
}

void Count(Confusion* c, bool predicted, bool truth) {
  if (predicted && truth) ++c->true_accept;
  if (predicted && !truth) ++c->false_accept;
  if (!predicted && !truth) ++c->true_reject;
  if (!predicted && truth) ++c->false_reject;
}

}  // namespace

bool TrainOptions::IsValid(std::string* why) const {
  OptionProblems check(why);
  check.Within(folds, AtLeast(2), "folds", "at least 2 folds");
  std::string part;
  check.Nested(logistic.IsValid(&part), "logistic.", part);
  return check.ok();
}

TransitionWeights TrainWeights(std::span<const PairFeatures> x, std::span<const uint8_t> accept,
                               const ComparisonWindow& window, const TrainOptions& options,
                               TrainReport* report) {
  const size_t n = x.size();
  if (std::string why; !options.IsValid(&why)) throw InputError("training options", why);
  if (accept.size() != n) throw WorkError("TrainWeights: features and labels disagree");
  const int folds = options.folds;
  size_t accepts = 0;
  for (uint8_t a : accept) accepts += a ? 1 : 0;
  if (n < 2 * static_cast<size_t>(folds)) {
    throw InputError("labels", std::to_string(n) + " labelled pairs; at least " +
                                   std::to_string(2 * folds) + " are needed for " +
                                   std::to_string(folds) + "-fold cross-validation");
  }
  if (accepts == 0 || accepts == n) {
    throw InputError("labels", std::string("every labelled pair is ") +
                                   (accepts == 0 ? "a reject" : "an accept") +
                                   ": both classes are needed");
  }
  TrainReport local;
  local.samples = static_cast<int64_t>(n);
  local.accepts = static_cast<int64_t>(accepts);
  local.folds = folds;

  std::vector<size_t> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::mt19937_64 rng(options.seed);
  std::shuffle(order.begin(), order.end(), rng);
  for (int f = 0; f < folds; ++f) {
    std::vector<size_t> train, test;
    for (size_t r = 0; r < n; ++r)
      (static_cast<int>(r % folds) == f ? test : train).push_back(order[r]);
    const Standardization s = Standardize(x, train);
    const LinearModel m1 = FitStage(x, accept, train, s, kCheapFeatureCount, options.logistic);
    const LinearModel m2 = FitStage(x, accept, train, s, kPairFeatureCount, options.logistic);
    for (size_t r : test) {
      Count(&local.stage1, Predicts(m1, s, x[r], kCheapFeatureCount), accept[r]);
      Count(&local.stage2, Predicts(m2, s, x[r], kPairFeatureCount), accept[r]);
    }
  }

  std::vector<size_t> all(n);
  std::iota(all.begin(), all.end(), 0);
  const Standardization s = Standardize(x, all);
  const LinearModel m1 = FitStage(x, accept, all, s, kCheapFeatureCount, options.logistic);
  const LinearModel m2 = FitStage(x, accept, all, s, kPairFeatureCount, options.logistic);
  TransitionWeights w;
  w.window = window;
  w.feature_mean = s.mean;
  w.feature_scale = s.scale;
  for (int k = 0; k < kCheapFeatureCount; ++k) w.stage1_weights[k] = m1.weights[k];
  w.stage1_bias = m1.bias;
  for (int k = 0; k < kPairFeatureCount; ++k) w.stage2_weights[k] = m2.weights[k];
  w.stage2_bias = m2.bias;
  w.training_json = local.ToJson();
  if (report) *report = local;
  return w;
}

// ---- stage 1 as a filter for stage 2 ----

std::vector<CheapDifference> SampleStage2Accepted(const SpriteStore& store,
                                                  const TransitionClassifier& classifier, int rows,
                                                  uint64_t seed, int threads) {
  const int32_t n = store.size();
  std::vector<int32_t> sample(n);
  std::iota(sample.begin(), sample.end(), 0);
  std::mt19937_64 rng(seed);
  std::shuffle(sample.begin(), sample.end(), rng);
  sample.resize(std::min<int32_t>(n, std::max(0, rows)));
  std::vector<CheapDifference> out;
  std::mutex mutex;
  std::atomic<size_t> cursor{0};
  auto work = [&] {
    std::vector<CheapDifference> local;
    for (size_t r; (r = cursor.fetch_add(1)) < sample.size();) {
      const int32_t i = sample[r];
      for (int32_t j = 0; j < n; ++j) {
        if (j == i) continue;
        const PairFeatures f = store.Features(i, j);
        if (classifier.Stage2Accepts(classifier.Distance(f)))
          local.push_back({f[0], f[1], f[2], f[3]});
      }
    }
    std::lock_guard<std::mutex> lock(mutex);
    out.insert(out.end(), local.begin(), local.end());
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(work);
  work();
  for (auto& t : pool) t.join();
  return out;
}

PopulationSample SamplePopulation(const SpriteStore& store, const TransitionClassifier& classifier,
                                  int rows, uint64_t seed, int threads) {
  PopulationSample out;
  const int32_t n = store.size();
  out.sprites = n;
  std::vector<int32_t> sample(n);
  std::iota(sample.begin(), sample.end(), 0);
  std::mt19937_64 rng(seed);
  std::shuffle(sample.begin(), sample.end(), rng);
  sample.resize(std::min<int32_t>(n, std::max(0, rows)));
  out.rows = sample;
  out.distance.assign(sample.size() * static_cast<size_t>(n), INFINITY);
  std::atomic<size_t> cursor{0};
  auto work = [&] {
    for (size_t r; (r = cursor.fetch_add(1)) < sample.size();) {
      const int32_t i = sample[r];
      float* row = &out.distance[r * n];
      for (int32_t j = 0; j < n; ++j) {
        if (j != i) row[j] = static_cast<float>(classifier.Distance(store.Features(i, j)));
      }
    }
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(work);
  work();
  for (auto& t : pool) t.join();
  return out;
}

namespace {

// The stage-2 threshold t2 = sum_k u2_k mean_k - b (TransitionClassifier), solved for b.
void SetStage2Threshold(double threshold, TransitionWeights* w) {
  double at_zero = 0;
  for (int k = 0; k < kPairFeatureCount; ++k)
    at_zero += w->stage2_weights[k] / w->feature_scale[k] * w->feature_mean[k];
  w->stage2_bias = at_zero - threshold;
}

}  // namespace

Stage2Calibration CalibrateStage2(std::span<const double> positive_distances,
                                  const PopulationSample& sample, double positive_rate,
                                  TransitionWeights* w) {
  if (positive_distances.empty())
    throw InputError("labels", "no accepted pair: stage 2 cannot be calibrated");
  if (!(positive_rate > 0 && positive_rate < 1)) {
    throw InputError("labels",
                     "the positive rate must be in (0, 1), got " + std::to_string(positive_rate));
  }
  if (sample.rows.empty() || sample.sprites < 2)
    throw InputError("sprites", "no sample to calibrate stage 2 on");
  std::vector<double> positives(positive_distances.begin(), positive_distances.end());
  std::sort(positives.begin(), positives.end());
  // Only the smallest distances can matter: at most a few times the expected positives.
  const double pairs = sample.pairs();
  const double expected_true = positive_rate * pairs;
  const size_t keep =
      std::min<size_t>(sample.distance.size(), static_cast<size_t>(20 * expected_true) + 1000);
  std::vector<float> d(sample.distance.begin(), sample.distance.end());
  std::nth_element(d.begin(), d.begin() + (keep - 1), d.end());
  d.resize(keep);
  std::sort(d.begin(), d.end());
  Stage2Calibration best;
  best.positive_rate = positive_rate;
  best.threshold = -1;
  for (size_t k = 0; k < d.size(); ++k) {
    if (!std::isfinite(d[k])) break;
    if (k + 1 < d.size() && d[k + 1] == d[k]) continue;  // the last of equal values
    const double t = d[k];
    const double recall =
        static_cast<double>(std::upper_bound(positives.begin(), positives.end(), t) -
                            positives.begin()) /
        positives.size();
    const double accepted = static_cast<double>(k + 1);
    const double precision = std::min(1.0, expected_true * recall / accepted);
    const double f1 = precision + recall > 0 ? 2 * precision * recall / (precision + recall) : 0.0;
    if (f1 > best.f1) {
      best.threshold = t;
      best.precision = precision;
      best.recall = recall;
      best.f1 = f1;
      best.accepts_per_sprite = accepted / sample.rows.size();
    }
  }
  if (best.threshold < 0)
    throw InputError("labels", "no stage-2 threshold accepts a labelled transition");
  // Nudge so that rounding keeps the chosen pairs inside.
  SetStage2Threshold(best.threshold + 1e-7 * (1.0 + std::abs(best.threshold)), w);
  return best;
}

Stage1Calibration FitStage1Filter(const SpriteStore& store, const PopulationSample& sample,
                                  double recall, uint64_t seed, TransitionWeights* w) {
  const TransitionClassifier classifier(*w);
  const int32_t n = sample.sprites;
  std::mt19937_64 rng(seed);
  // Positives: every pair stage 2 accepts; negatives: about 20 per positive, at random.
  int64_t positives = 0;
  for (float d : sample.distance) positives += classifier.Stage2Accepts(d);
  Stage1Calibration c;
  c.recall = recall;
  c.stage2_accepts = positives;
  if (positives == 0) return c;
  const double negative_share =
      std::min(1.0, 20.0 * positives / std::max(1.0, sample.pairs() - positives));
  std::bernoulli_distribution take(negative_share);
  std::vector<CheapDifference> x;
  std::vector<uint8_t> y;
  for (size_t r = 0; r < sample.rows.size(); ++r) {
    const int32_t i = sample.rows[r];
    for (int32_t j = 0; j < n; ++j) {
      if (j == i) continue;
      const bool accepted = classifier.Stage2Accepts(sample.distance[r * n + j]);
      if (!accepted && !take(rng)) continue;
      x.push_back(CheapDiff(store.cheap(i), store.cheap(j)));
      y.push_back(accepted);
    }
  }
  if (x.size() > static_cast<size_t>(positives)) {  // both classes present
    std::vector<double> z(x.size() * kCheapFeatureCount);
    for (size_t s = 0; s < x.size(); ++s) {
      for (int k = 0; k < kCheapFeatureCount; ++k) {
        z[s * kCheapFeatureCount + k] = (x[s][k] - w->feature_mean[k]) / w->feature_scale[k];
      }
    }
    const LinearModel m = FitLogistic(z, kCheapFeatureCount, y, LogisticOptions{});
    double total = 0;
    for (double v : m.weights) total += v;
    if (total > 0) {
      for (int k = 0; k < kCheapFeatureCount; ++k) w->stage1_weights[k] = m.weights[k];
    }
  }
  std::vector<CheapDifference> accepted;
  for (size_t s = 0; s < x.size(); ++s) {
    if (y[s]) accepted.push_back(x[s]);
  }
  CalibrateStage1(accepted, recall, w);
  // Candidates per sprite with the new stage 1, on the same sample.
  const TransitionClassifier filter(*w);
  int64_t candidates = 0;
  for (int32_t i : sample.rows) {
    for (int32_t j = 0; j < n; ++j)
      candidates += j != i && filter.Stage1Accepts(store.cheap(i), store.cheap(j));
  }
  c.candidates_per_sprite = static_cast<double>(candidates) / sample.rows.size();
  c.fewer_than_all = candidates > 0 ? sample.pairs() / candidates : INFINITY;
  return c;
}

double CalibrateStage1(std::span<const CheapDifference> accepted, double recall,
                       TransitionWeights* w) {
  const double previous = w->stage1_bias;
  if (accepted.empty()) return previous;
  std::vector<double> values;
  values.reserve(accepted.size());
  for (const CheapDifference& d : accepted) {
    double v = 0;
    for (int k = 0; k < kCheapFeatureCount; ++k) {
      v += w->stage1_weights[k] * (d[k] - w->feature_mean[k]) / w->feature_scale[k];
    }
    values.push_back(v);
  }
  std::sort(values.begin(), values.end());
  const double q = std::clamp(recall, 0.0, 1.0);
  const size_t k = std::min(values.size() - 1,
                            static_cast<size_t>(std::max(0.0, std::ceil(q * values.size()) - 1.0)));
  // Accept when w.z + b <= 0: b = -values[k], nudged so that rounding keeps values[k] inside.
  w->stage1_bias = -values[k] - 1e-9 * (1.0 + std::abs(values[k]));
  return previous;
}

}  // namespace ss
