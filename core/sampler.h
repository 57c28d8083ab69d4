// Equalisation (paper Fig. 1 line 8; docs/ALGORITHM.md step 4) on a parametric
// surface: the CurveSamples (core/curve_samples.h) of a CurveTree, which a
// SampleCursor (core/sample_cursor.h) yields by index range or region, in
// curve order.
//
// Sample k has mass coordinate q_k S_M; core/leaf_walk.h places it in its
// leaf and follows the leaf's model, and the surface is evaluated over the
// batch. The result is a pure function of (tree, sequence, k).
//
// Thread-safety: Sampler is immutable and thread-safe.
#ifndef SFCSAMPLER_CORE_SAMPLER_H_
#define SFCSAMPLER_CORE_SAMPLER_H_

#include <memory>
#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "core/curve_samples.h"
#include "core/curve_tree.h"
#include "core/density.h"
#include "core/sample_cursor.h"
#include "core/sequence.h"
#include "core/surface.h"
#include "core/tree_warp.h"
#include "core/types/region.h"
#include "core/types/sample_batch.h"

namespace sfc {

class Sampler final : public CurveSamples {
 public:
  // REQUIRES: `tree` was built from `surface` and `density`.
  Sampler(std::shared_ptr<const CurveTree> tree, std::shared_ptr<const Surface> surface,
          std::shared_ptr<const Density> density, Sequence sequence);

  const CurveTree& tree() const { return *tree_; }
  const Surface& surface() const { return *surface_; }
  const Density& density() const { return *density_; }

  // Every sequence: a two-dimensional one (sobol) through a TreeWarp of the
  // tree, made with the sampler (O(leaves)).
  absl::Status AcceptsSequence(const Sequence&) const override { return absl::OkStatus(); }
  // The points (a[i], b[i]) of the unit square through the TreeWarp.
  // REQUIRES: a two-dimensional sequence.
  void WarpMany(size_t n, const double* a, const double* b, CurveAddress* out) const override;
  // The warp of a two-dimensional sequence; null for the others.
  const TreeWarp* warp() const { return warp_.get(); }
  // The tree's leaf count.
  uint32_t AddressLeafBound() const override { return static_cast<uint32_t>(tree_->leaf_count()); }

  // Every region kind: a parameter rectangle or a 3D box.
  absl::Status AcceptsRegion(const Region&) const override { return absl::OkStatus(); }
  // The leaves of the cells that may meet `region`, by a descent of the
  // tree's cells bounded by Surface::Bound.
  absl::Status PlanRegion(const Region& region, uint64_t begin, uint64_t end,
                          std::vector<IndexSegment>* segments) const override;
  // Places samples through a LeafWalk of its own and evaluates the surface.
  // Errors: INVALID_ARGUMENT when the surface is not finite at a sample.
  std::unique_ptr<SampleFiller> NewFiller(const Region& region,
                                          const SampleFields& fields) const override;

 private:
  std::shared_ptr<const CurveTree> tree_;
  std::shared_ptr<const Surface> surface_;
  std::shared_ptr<const Density> density_;
  std::unique_ptr<const TreeWarp> warp_;
};

}  // namespace sfc

#endif  // SFCSAMPLER_CORE_SAMPLER_H_
