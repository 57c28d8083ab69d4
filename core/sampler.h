// Equalisation (paper Fig. 1 line 8; ALGORITHM.md step 4) and the samples it
// yields, by index range or region, in curve order.
//
// Sample k lands in the leaf l with S_{l-1} <= q_k S_M < S_l. Inside the leaf
// it follows the leaf's model (ALGORITHM.md, "Inside a leaf, follow the
// model"): the fraction t = (q_k S_M - S_{l-1}) / s_l descends the leaf's own
// curve, at each level entering the child whose share of the model's exact
// integral holds t. Once the sub-cell reached carries less than
// kNegligibleSamples of one sample (counted at the tree's grade, so every
// sequence on one tree places a given t alike), the rest of t is followed as pure curve
// bits for continuation_levels() more levels (all 52 bits of t for Hilbert),
// and the sample sits at the centre of the cell reached. The descent is kept
// on a per-level stack that consecutive samples of one leaf share. Nothing is
// snapped to leaf centres, and the result is a pure function of
// (tree, sequence, k): the stack only caches values computed the same way.
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
  // The leaf holding mass coordinate m (zero-mass leaves are never chosen).
  size_t LeafForMass(double m) const;
  // First k in [0, count) whose mass coordinate is >= m, for monotone
  // sequences; count if none.
  uint64_t FirstIndexAtOrAbove(double m) const;

 private:
  std::shared_ptr<const CurveTree> tree_;
  std::shared_ptr<const Surface> surface_;
  std::shared_ptr<const Density> density_;
  Sequence sequence_;
  size_t last_positive_leaf_ = 0;
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
  // A sub-cell of the model descent: leaf-fraction interval [t0, t1), its
  // square [x0, x0 + side) x [y0, y0 + side) in leaf units, its orientation
  // and its start along the leaf's curve (a fraction of the leaf's span).
  struct Level {
    double t0, t1, x0, y0, side, pos, span;  // span: the level's share of the leaf's curve
    int state;
    int children = 0;  // 0 until bounds[] is filled: then the curve's arity
    double bounds[9];  // upper t of each child, in curve order
  };
  // The last leaf decoded and its descent, reused by consecutive samples; one
  // per thread.
  struct LeafCache {
    size_t leaf = SIZE_MAX;
    CurveTree::Cell cell{};
    double samples = 0;  // the leaf's mass in samples
    std::vector<Level> stack;
  };

 public:
  // Below this many samples' worth a sub-cell's placement is pure curve bits.
  static constexpr double kNegligibleSamples = 1.0 / 8;
  // The model descent stops after this many levels in any case.
  static constexpr int kMaxModelLevels = 40;

 private:

  SampleCursor(std::shared_ptr<const Sampler> sampler, Region region, SampleFields fields);
  absl::Status PlanRegion(uint64_t begin, uint64_t end);
  absl::Status Emit(uint64_t k, LeafCache& cache, SampleBatch* batch, bool* kept) const;
  // Emits [k0, k1) (all kept: no region) split over threads_ threads.
  absl::Status EmitParallel(uint64_t k0, uint64_t k1, SampleBatch* batch);

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
  LeafCache cache_;
  int threads_ = 1;
};

}  // namespace sfc

#endif  // SFCSAMPLER_CORE_SAMPLER_H_
