// Equalisation along the mesh curve (docs/ALGORITHM.md step 4): the
// CurveSamples (core/curve_samples.h) of a MeshCurveTree, which core's
// SampleCursor (core/sample_cursor.h) yields by index range and region.
//
// Sample k lands in the leaf l with S_{l-1} <= q_k S_M < S_l; its fraction
// t = (q_k S_M - S_{l-1}) / s_l continues down the leaf's own curve
// (MeshCurveTree::Descend) to all 52 bits of t: no snapping, no duplicates.
// Every sample is a pure function of (mesh, density, tree options, sequence,
// seed, k).
//
// Columns: index; u, v = barycentric coordinates of corners 1 and 2 of the
// sample's triangle (corner 0's is 1 - u - v); triangle = the triangle's
// index in the loaded mesh; x, y, z on the flat triangle; optional normal
// (interpolated vertex normals when the mesh has them, else the face normal),
// density, and curve position = (rank of the triangle on the curve + area
// fraction along its own curve) / triangles, in [0, 1).
//
// Thread-safety: MeshSampler is immutable and thread-safe.
#ifndef SFCSAMPLER_MESH_MESH_SAMPLER_H_
#define SFCSAMPLER_MESH_MESH_SAMPLER_H_

#include <algorithm>
#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "absl/status/status.h"
#include "core/curve_samples.h"
#include "core/sample_cursor.h"
#include "core/sequence.h"
#include "core/types/region.h"
#include "core/types/sample_batch.h"
#include "core/vector_math.h"
#include "mesh/mesh_curve_tree.h"
#include "mesh/mesh_warp.h"

namespace sfc {

// One sample, computed alone.
struct MeshSample {
  uint64_t index = 0;
  uint32_t triangle = 0;
  std::array<double, 3> bary{};  // corners 0, 1, 2
  Vec3 position;
  double curve_position = 0;
  size_t leaf = 0;
};

class MeshSampler final : public CurveSamples {
 public:
  MeshSampler(std::shared_ptr<const MeshCurveTree> tree, Sequence sequence);

  const MeshCurveTree& tree() const { return *tree_; }

  // The leaf holding mass coordinate m (zero-mass leaves are never chosen).
  size_t LeafForMass(double m) const;
  // The same leaf, found by walking forward from leaf `from` when m lies at
  // most a few leaves past it (samples and leaves advance together), else
  // by LeafForMass. REQUIRES: from < leaf_count() and m >= mass_ends()[from].
  size_t LeafForMassAfter(size_t from, double m) const {
    const auto& ends = tree_->mass_ends();
    const size_t stop = std::min(ends.size(), from + 9);
    for (size_t l = from + 1; l < stop; ++l) {
      if (ends[l] > m) return l;
    }
    return LeafForMass(m);
  }
  // Sample k. REQUIRES: k < sequence().count().
  MeshSample At(uint64_t k) const;
  // Sample k's fraction of leaf l's mass, in [0, 1).
  double FractionInLeaf(double m, size_t l) const {
    const double begin = tree_->mass_begin(l);
    const double t = (m - begin) / (tree_->mass_ends()[l] - begin);
    if (!(t >= 0)) return 0;
    if (!(t < 1)) return math::kBelowOne;
    return t;
  }
  // Sample at mass coordinate m inside leaf l with cell `cell` (= LeafCell(l)).
  MeshSample AtMass(uint64_t k, double m, size_t l, const MeshCurveTree::Cell& cell) const;

  // Every sequence: a two-dimensional one (sobol) through a MeshWarp made
  // with the sampler (O(leaves) time, at most 8 MB, per request; outside the
  // stream's memory budget, like the cursor's per-thread scratch).
  absl::Status AcceptsSequence(const Sequence&) const override { return absl::OkStatus(); }
  // The points (a[i], b[i]) of the unit square through the MeshWarp.
  // REQUIRES: a two-dimensional sequence.
  void WarpMany(size_t n, const double* a, const double* b, CurveAddress* out) const override;
  const MeshWarp* warp() const { return warp_.get(); }
  // The tree's leaf count.
  uint32_t AddressLeafBound() const override { return static_cast<uint32_t>(tree_->leaf_count()); }

  // INVALID_ARGUMENT for a parameter rectangle: a mesh has no parameter
  // square (use a 3D box).
  absl::Status AcceptsRegion(const Region& region) const override;
  // The runs of triangles whose bounding boxes meet the box: the cost is
  // proportional to those triangles.
  absl::Status PlanRegion(const Region& region, uint64_t begin, uint64_t end,
                          std::vector<IndexSegment>* segments) const override;
  bool has_triangles() const override { return true; }
  // Descends samples in chunks (MeshCurveTree::DescendMany). Errors:
  // INVALID_ARGUMENT when the density is negative or not finite at a sample
  // in the region (only when the density column is asked for).
  std::unique_ptr<SampleFiller> NewFiller(const Region& region,
                                          const SampleFields& fields) const override;

 private:
  std::shared_ptr<const MeshCurveTree> tree_;
  size_t last_positive_leaf_ = 0;
  std::unique_ptr<const MeshWarp> warp_;  // two-dimensional sequences only
};

}  // namespace sfc

#endif  // SFCSAMPLER_MESH_MESH_SAMPLER_H_
