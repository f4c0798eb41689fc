#pragma once
// Rows of the matching cost c_t(s) between target frames t and source frames s, computed a
// few target rows at a time so the matcher never holds the whole T x S matrix.
#include <vector>

#include "animate/skeleton/descriptor.h"

namespace ss {

class CostRows {
 public:
  virtual ~CostRows() = default;
  virtual int targets() const = 0;
  virtual int sources() const = 0;
  // Rows t0 .. t0+n-1 into out[(t - t0) * sources() + s]. +inf marks a source frame that
  // may never be chosen.
  virtual void Compute(int t0, int n, float* out) const = 0;
  // One value c_t(s) (path costs); by default computes the whole row.
  virtual float At(int t, int s) const;
};

// An explicit matrix (tests, small problems): values[t * sources + s].
class DenseCostRows final : public CostRows {
 public:
  DenseCostRows(int targets, int sources, std::vector<float> values);
  int targets() const override { return targets_; }
  int sources() const override { return sources_; }
  void Compute(int t0, int n, float* out) const override;
  float At(int t, int s) const override { return at(t, s); }
  float at(int t, int s) const { return values_[static_cast<size_t>(t) * sources_ + s]; }

 private:
  int targets_, sources_;
  std::vector<float> values_;
};

// PoseCost between target and source descriptors, vectorized: complete frames use
// |a|^2 + |b|^2 - 2 a.b over the features (a dense, GEMM-like kernel); a target with a
// missing term uses the direct sum over its terms; an incomplete source frame is
// computed exactly like PoseCost. Source frames whose coverage (share of the pose terms'
// weight they have) is below `min_source_coverage` are excluded (+inf).
class DescriptorCostRows final : public CostRows {
 public:
  DescriptorCostRows(const PoseDescriptors& targets, const PoseDescriptors& sources,
                     float min_source_coverage = 0.5f);
  int targets() const override { return targets_->count; }
  int sources() const override { return sources_->count; }
  void Compute(int t0, int n, float* out) const override;
  float At(int t, int s) const override;  // PoseCost directly (+inf when excluded)
  // Number of source frames that can be chosen.
  int usable_sources() const { return sources_->count - static_cast<int>(excluded_.size()); }

 private:
  const PoseDescriptors* targets_;
  const PoseDescriptors* sources_;
  int padded_ = 0;  // sources rounded up to the kernel's width
  // Packed per chunk of 16 sources: [(s / 16) * dim + k) * 16 + s % 16], so a kernel step
  // reads one contiguous run (dim x 16 floats) instead of dim rows a whole source row apart.
  std::vector<float> source_features_;
  std::vector<float> source_norm_;  // sum_k w_k b_k^2 / W, complete sources
  std::vector<int> incomplete_;     // usable but incomplete source frames
  std::vector<int> excluded_;       // coverage below the minimum
};

}  // namespace ss
