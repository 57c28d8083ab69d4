// Equalisation (paper Fig. 1 line 8; docs/ALGORITHM.md step 4) and the samples it
// yields, by index range or region, in curve order.
//
// Sample k has mass coordinate q_k S_M; core/leaf_walk.h places it in its
// leaf and follows the leaf's model. A cursor hands the walk its samples in
// curve order, a batch at a time: columns are sized once and filled in place,
// the surface is evaluated over the batch, and a region drops what lies
// outside it afterwards. The result is a pure function of (tree, sequence, k).
//
// Thread-safety: Sampler is immutable and thread-safe. A SampleCursor is used
// by one thread at a time.
#ifndef SFCSAMPLER_CORE_SAMPLER_H_
#define SFCSAMPLER_CORE_SAMPLER_H_

#include <memory>
#include <utility>
#include <vector>

#include "absl/status/statusor.h"
#include "core/curve_tree.h"
#include "core/density.h"
#include "core/leaf_walk.h"
#include "core/region.h"
#include "core/sample_batch.h"
#include "core/sequence.h"
#include "core/surface.h"

namespace sfc {

class Sampler {
 public:
  // REQUIRES: `tree` was built from `surface` and `density`.
  Sampler(std::shared_ptr<const CurveTree> tree, std::shared_ptr<const Surface> surface,
          std::shared_ptr<const Density> density, Sequence sequence);

  const CurveTree& tree() const { return *tree_; }
  const Surface& surface() const { return *surface_; }
  const Density& density() const { return *density_; }
  const Sequence& sequence() const { return sequence_; }

  // q_k S_M: sample k's mass coordinate along the curve.
  double MassCoordinate(uint64_t k) const { return sequence_.At(k) * tree_->total_mass(); }
  // First k in [0, count) whose mass coordinate is >= m, for monotone
  // sequences; count if none.
  uint64_t FirstIndexAtOrAbove(double m) const;

 private:
  std::shared_ptr<const CurveTree> tree_;
  std::shared_ptr<const Surface> surface_;
  std::shared_ptr<const Density> density_;
  Sequence sequence_;
};

class SampleCursor {
 public:
  // Samples with index in [begin, end) that lie in `region`, in curve order.
  // For monotone sequences the cost is proportional to the samples emitted
  // plus the tree cells on the region's boundary; other sequences sort the
  // range by curve position first (cost O(n log n), n = end - begin).
  // Errors: INVALID_ARGUMENT for begin > end, end > count, or an empty region;
  // RESOURCE_EXHAUSTED is not raised here (the caller bounds count).
  // `threads` > 1 lets Next() fill large batches of plain index ranges with
  // that many threads; the samples and their order do not change.
  static absl::StatusOr<std::unique_ptr<SampleCursor>> Create(std::shared_ptr<const Sampler> sampler,
                                                              uint64_t begin, uint64_t end,
                                                              const Region& region,
                                                              const SampleFields& fields,
                                                              int threads = 1);

  // Appends up to `max` samples to `batch` (which it does not clear) and
  // returns how many; 0 once the cursor is exhausted. Errors: INVALID_ARGUMENT
  // when the surface or density is not finite at a sample.
  absl::StatusOr<size_t> Next(size_t max, SampleBatch* batch);

 private:
  // The batch's columns from one row on; null for the columns not asked for.
  struct Rows {
    uint64_t* index;
    double *u, *v, *x, *y, *z, *nx, *ny, *nz, *density, *curve_position;
    Rows From(size_t offset) const;
  };

  SampleCursor(std::shared_ptr<const Sampler> sampler, Region region, SampleFields fields);
  absl::Status PlanRegion(uint64_t begin, uint64_t end);
  // Grows the batch's columns by n rows and returns the new rows.
  Rows Grow(SampleBatch* batch, size_t n) const;
  // Shrinks the batch's columns to `rows` rows.
  void Truncate(SampleBatch* batch, size_t rows) const;
  // Fills n rows with samples k0 + i (order null) or order[i]; their mass
  // coordinates must not decrease. Errors: INVALID_ARGUMENT when the surface
  // is not finite at one.
  absl::Status Fill(uint64_t k0, const uint64_t* order, size_t n, LeafWalk& walk,
                    const Rows& out) const;
  // Appends the samples k0 + i (or order[i]), i < n, that lie in the region;
  // returns how many.
  absl::StatusOr<size_t> Generate(uint64_t k0, const uint64_t* order, size_t n,
                                  SampleBatch* batch);
  // Appends [k0, k0 + n) (all kept: no region), split over threads_ threads.
  absl::Status GenerateParallel(uint64_t k0, size_t n, SampleBatch* batch);

  struct Segment {
    uint64_t begin, end;
  };

  const std::shared_ptr<const Sampler> sampler_;
  const Region region_;
  const SampleFields fields_;
  // Monotone sequences: index segments in curve order.
  std::vector<Segment> segments_;
  size_t segment_ = 0;
  uint64_t next_k_ = 0;
  // Other sequences: the indices sorted by curve position.
  std::vector<uint64_t> order_;
  size_t order_pos_ = 0;
  bool use_order_ = false;
  LeafWalk walk_;  // the cursor's own walk; parallel parts make their own
  int threads_ = 1;
};

}  // namespace sfc

#endif  // SFCSAMPLER_CORE_SAMPLER_H_
