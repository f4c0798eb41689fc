#include "animate/skeleton/descriptor.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "core/option_checks.h"

namespace ss {

bool DescriptorOptions::IsValid(std::string* why) const {
  OptionProblems check(why);
  const auto at_least_0 = [&](double v, const char* field) {
    check(std::isfinite(v) && v >= 0, field,
          "must be a finite number >= 0, got " + OptionProblems::Num(v));
  };
  const auto positive = [&](double v, const char* field, const char* what) {
    check(std::isfinite(v) && v > 0, field,
          std::string("must be a positive ") + what + ", got " + OptionProblems::Num(v));
  };
  at_least_0(angle_weight, "angle_weight");
  at_least_0(ratio_weight, "ratio_weight");
  at_least_0(orientation_weight, "orientation_weight");
  check(!(angle_weight >= 0 && ratio_weight >= 0) || angle_weight + ratio_weight > 0,
        "angle_weight", "angle_weight + ratio_weight must be > 0 (the descriptor would be empty)");
  at_least_0(min_limb_px, "min_limb_px");
  at_least_0(no_overlap_cost, "no_overlap_cost");
  at_least_0(motion_weight, "motion_weight");
  if (motion_weight > 0) {
    positive(motion_window_s, "motion_window_s", "number of seconds");
    positive(motion_scale, "motion_scale", "number");
  }
  at_least_0(root_motion_weight, "root_motion_weight");
  if (root_motion_weight > 0) positive(root_motion_scale, "root_motion_scale", "number");
  positive(default_fps, "default_fps", "frame rate");
  return check.ok();
}

DescriptorLayout MakeDescriptorLayout(const SkeletonDef& def, const DescriptorOptions& options) {
  DescriptorLayout layout;
  layout.pairs = static_cast<int>(def.pairs.size());
  const bool orientation = options.orientation_weight > 0;
  layout.groups = layout.pairs + (orientation ? 1 : 0);
  layout.dim = 3 * layout.pairs + (orientation ? 2 : 0);
  for (int p = 0; p < layout.pairs; ++p) {
    layout.feature_weight.insert(
        layout.feature_weight.end(),
        {options.angle_weight / 2, options.angle_weight / 2, options.ratio_weight});
    layout.feature_group.insert(layout.feature_group.end(), {p, p, p});
    layout.group_weight.push_back(options.angle_weight + options.ratio_weight);
  }
  if (orientation) {
    layout.feature_weight.insert(layout.feature_weight.end(),
                                 {options.orientation_weight / 2, options.orientation_weight / 2});
    layout.feature_group.insert(layout.feature_group.end(), {layout.pairs, layout.pairs});
    layout.group_weight.push_back(options.orientation_weight);
  }
  layout.first_motion_group = layout.groups;
  layout.first_motion_feature = layout.dim;
  for (float w : layout.group_weight) layout.pose_total_weight += w;
  if (options.motion_weight > 0) {
    for (int p = 0; p < layout.pairs; ++p) {
      layout.feature_weight.push_back(options.motion_weight);
      layout.feature_group.push_back(layout.groups);
      layout.group_weight.push_back(options.motion_weight);
      ++layout.groups;
      ++layout.dim;
    }
    if (options.root_motion_weight > 0) {
      layout.feature_weight.push_back(options.root_motion_weight);
      layout.feature_group.push_back(layout.groups);
      layout.group_weight.push_back(options.root_motion_weight);
      ++layout.groups;
      ++layout.dim;
    }
  }
  for (float w : layout.group_weight) layout.total_weight += w;
  layout.no_overlap_cost = options.no_overlap_cost;
  return layout;
}

namespace {

struct Vec2 {
  float x = 0, y = 0;
};

// The end of `limb` that is not `joint`.
int OtherEnd(const Limb& limb, int joint) { return limb.from == joint ? limb.to : limb.from; }

// Fills frame i's features of one clip into `out` (count = out.count, offset `i`).
void Describe(const SkeletonDef& def, const SkeletonFrame& frame, const DescriptorOptions& options,
              PoseDescriptors* out, int i) {
  const DescriptorLayout& layout = out->layout;
  const size_t n = out->count;
  auto vec = [&](int from, int to, Vec2* v) {
    const JointSample& a = frame.joints[from];
    const JointSample& b = frame.joints[to];
    if (!a.present || !b.present) return false;
    v->x = b.x_px - a.x_px;
    v->y = b.y_px - a.y_px;
    return std::hypot(v->x, v->y) >= std::max(options.min_limb_px, 1e-6f);
  };
  float weight = 0;
  for (int p = 0; p < layout.pairs; ++p) {
    const LimbPair& pair = def.pairs[p];
    Vec2 u, v;
    const bool ok = vec(pair.joint, OtherEnd(def.limbs[pair.limb_a], pair.joint), &u) &&
                    vec(pair.joint, OtherEnd(def.limbs[pair.limb_b], pair.joint), &v);
    out->present[p * n + i] = ok ? 1 : 0;
    if (!ok) continue;
    const double lu = std::hypot(u.x, u.y), lv = std::hypot(v.x, v.y);
    const double cos_angle =
        (static_cast<double>(u.x) * v.x + static_cast<double>(u.y) * v.y) / (lu * lv);
    const double sin_angle =
        (static_cast<double>(u.x) * v.y - static_cast<double>(u.y) * v.x) / (lu * lv);
    out->features[(3 * p) * n + i] = static_cast<float>(cos_angle);
    out->features[(3 * p + 1) * n + i] = static_cast<float>(sin_angle);
    out->features[(3 * p + 2) * n + i] = static_cast<float>(std::log(lv / lu));
    weight += layout.group_weight[p];
  }
  if (layout.groups > layout.pairs) {
    const int g = layout.pairs;
    const Limb& root = def.limbs[def.root_limb];
    Vec2 u;
    const bool ok = vec(root.from, root.to, &u);
    out->present[g * n + i] = ok ? 1 : 0;
    if (ok) {
      const double lu = std::hypot(u.x, u.y);
      out->features[(3 * g) * n + i] = static_cast<float>(u.x / lu);
      out->features[(3 * g + 1) * n + i] = static_cast<float>(u.y / lu);
      weight += layout.group_weight[g];
    }
  }
  out->present_weight[i] = weight;
  out->pose_weight[i] = weight;
}

// Subtracts, per pair, the median log ratio over frames [begin, end) that have it.
void NormalizeRatios(PoseDescriptors* d, int begin, int end) {
  const size_t n = d->count;
  std::vector<float> values;
  for (int p = 0; p < d->layout.pairs; ++p) {
    values.clear();
    float* ratio = &d->features[(3 * p + 2) * n];
    for (int i = begin; i < end; ++i) {
      if (d->present[p * n + i]) values.push_back(ratio[i]);
    }
    if (values.empty()) continue;
    const size_t mid = values.size() / 2;
    std::nth_element(values.begin(), values.begin() + mid, values.end());
    float median = values[mid];
    if (values.size() % 2 == 0)
      median = (median + *std::max_element(values.begin(), values.begin() + mid)) / 2;
    for (int i = begin; i < end; ++i) {
      if (d->present[p * n + i]) ratio[i] -= median;
    }
  }
}

// The motion features of the clip at [begin, begin + clip.size()) from its pose features:
// per frame, the frames a (the last at or before t - h) and b (the first at or after
// t + h), clipped to the clip; Δt = t_b - t_a must lie in [h, 4h] (shorter: a clip too
// short to measure; longer: a gap in the frame numbers).
void DescribeMotion(const SkeletonSequence& clip, double fps, const DescriptorOptions& options,
                    PoseDescriptors* d, int begin) {
  const DescriptorLayout& layout = d->layout;
  if (layout.first_motion_group == layout.groups) return;
  const size_t count = d->count;
  const int n = clip.size();
  const double h = options.motion_window_s;
  auto time = [&](int i) { return static_cast<double>(clip.frames[i].frame) / fps; };
  // a thousandth of a frame: 0.2f is not 0.2 nor 5 frames at 25 fps exactly
  const double eps = 1e-3 / fps;
  int a = 0, b = 0;
  for (int i = 0; i < n; ++i) {
    const double t = time(i);
    while (a + 1 <= i && time(a + 1) <= t - h + eps) ++a;
    b = std::max(b, i);
    while (b + 1 < n && time(b) < t + h - eps) ++b;
    const double dt = time(b) - time(a);
    if (!(dt >= h - eps) || dt > 4 * h) continue;
    const int ia = begin + a, ib = begin + b, ii = begin + i;
    for (int p = 0; p < layout.pairs; ++p) {
      if (!d->has(p, ia) || !d->has(p, ib)) continue;
      double sum = 0;
      for (int k = 3 * p; k < 3 * p + 3; ++k) {
        const double diff =
            static_cast<double>(d->features[k * count + ib]) - d->features[k * count + ia];
        sum += diff * diff;
      }
      const double rate = std::sqrt(sum) / dt;
      const int g = layout.first_motion_group + p;
      d->features[(layout.first_motion_feature + p) * count + ii] =
          static_cast<float>(rate / (rate + options.motion_scale));
      d->present[g * count + ii] = 1;
      d->present_weight[ii] += layout.group_weight[g];
    }
    // The root limb's midpoint.
    const int g = layout.first_motion_group + layout.pairs;
    if (g >= layout.groups) continue;
    const Limb& root = clip.skeleton.limbs[clip.skeleton.root_limb];
    const auto& ja = clip.frames[a].joints;
    const auto& jb = clip.frames[b].joints;
    if (!ja[root.from].present || !ja[root.to].present || !jb[root.from].present ||
        !jb[root.to].present)
      continue;
    const double length =
        (std::hypot(ja[root.to].x_px - ja[root.from].x_px, ja[root.to].y_px - ja[root.from].y_px) +
         std::hypot(jb[root.to].x_px - jb[root.from].x_px, jb[root.to].y_px - jb[root.from].y_px)) /
        2;
    if (!(length >= std::max(options.min_limb_px, 1e-6f))) continue;
    const double dx =
        (jb[root.from].x_px + jb[root.to].x_px - ja[root.from].x_px - ja[root.to].x_px) / 2.0;
    const double dy =
        (jb[root.from].y_px + jb[root.to].y_px - ja[root.from].y_px - ja[root.to].y_px) / 2.0;
    const double speed = std::hypot(dx, dy) / length / dt;
    d->features[(layout.first_motion_feature + layout.pairs) * count + ii] =
        static_cast<float>(speed / (speed + options.root_motion_scale));
    d->present[g * count + ii] = 1;
    d->present_weight[ii] += layout.group_weight[g];
  }
}

}  // namespace

PoseDescriptors ComputeDescriptors(const std::vector<const SkeletonSequence*>& clips,
                                   const DescriptorOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) throw InputError("descriptor options", why);
  if (clips.empty()) throw InputError("skeletons", "no skeleton sequence given");
  const SkeletonDef& def = clips.front()->skeleton;
  PoseDescriptors d;
  d.layout = MakeDescriptorLayout(def, options);
  for (const auto* clip : clips) {
    const auto& limbs = clip->skeleton.limbs;
    const bool same_limbs =
        limbs.size() == def.limbs.size() &&
        std::equal(limbs.begin(), limbs.end(), def.limbs.begin(),
                   [](const Limb& x, const Limb& y) { return x.from == y.from && x.to == y.to; });
    if (clip->skeleton.joints != def.joints || !same_limbs) {
      throw InputError(clip->clip.empty() ? "skeletons" : clip->clip,
                       "skeleton '" + clip->skeleton.name + "' differs from '" + def.name +
                           "': sources and targets need the same skeletal structure");
    }
    d.count += clip->size();
  }
  d.features.assign(static_cast<size_t>(d.layout.dim) * d.count, 0.0f);
  d.present.assign(static_cast<size_t>(d.layout.groups) * d.count, 0);
  d.present_weight.assign(d.count, 0.0f);
  d.pose_weight.assign(d.count, 0.0f);
  int i = 0;
  for (const auto* clip : clips) {
    const int begin = i;
    for (const auto& frame : clip->frames) {
      if (frame.joints.size() != def.joints.size()) {
        throw InputError(clip->clip.empty() ? "skeletons" : clip->clip,
                         "frame " + std::to_string(frame.frame) + " has " +
                             std::to_string(frame.joints.size()) + " joints, skeleton '" +
                             def.name + "' has " + std::to_string(def.joints.size()));
      }
      Describe(def, frame, options, &d, i++);
    }
    if (options.normalize_ratios) NormalizeRatios(&d, begin, i);
    const double fps = clip->fps > 0 ? clip->fps : options.default_fps;
    d.clip_starts.push_back(begin);
    d.clip_fps.push_back(fps);
    DescribeMotion(*clip, fps, options, &d, begin);
  }
  return d;
}

PoseDescriptors ComputeDescriptors(const SkeletonSequence& sequence,
                                   const DescriptorOptions& options) {
  return ComputeDescriptors(std::vector<const SkeletonSequence*>{&sequence}, options);
}

float PoseCost(const PoseDescriptors& a, int i, const PoseDescriptors& b, int j, bool motion) {
  const DescriptorLayout& layout = a.layout;
  if (a.present_weight[i] <= 0) return 0.0f;
  const int groups = motion ? layout.groups : layout.first_motion_group;
  const int dim = motion ? layout.dim : layout.first_motion_feature;
  double numerator = 0, denominator = 0;
  for (int g = 0; g < groups; ++g) {
    if (!a.has(g, i) || !b.has(g, j)) continue;
    denominator += layout.group_weight[g];
  }
  if (denominator <= 0) return layout.no_overlap_cost;
  for (int k = 0; k < dim; ++k) {
    const int g = layout.feature_group[k];
    if (!a.has(g, i) || !b.has(g, j)) continue;
    const double diff = static_cast<double>(a.feature(k, i)) - b.feature(k, j);
    numerator += layout.feature_weight[k] * diff * diff;
  }
  return static_cast<float>(numerator / denominator);
}

std::vector<float> SequentialCost(const PoseDescriptors& sequence) {
  std::vector<float> cost;
  for (int t = 0; t + 1 < sequence.count; ++t)
    cost.push_back(PoseCost(sequence, t, sequence, t + 1, false));
  return cost;
}

double FrameRateAt(const PoseDescriptors& d, int i) {
  const auto it = std::upper_bound(d.clip_starts.begin(), d.clip_starts.end(), i);
  if (it == d.clip_starts.begin()) return 30.0;
  return d.clip_fps[it - d.clip_starts.begin() - 1];
}

}  // namespace ss
