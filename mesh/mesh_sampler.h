// Equalisation along the mesh curve (docs/ALGORITHM.md step 4) and a cursor with
// the contract of core's SampleCursor (core/sampler.h).
//
// Sample k lands in the leaf l with S_{l-1} <= q_k S_M < S_l; its fraction
// t = (q_k S_M - S_{l-1}) / s_l continues down the leaf's own curve
// (MeshCurveTree::Descend) to all 52 bits of t: no snapping, no duplicates.
// Every sample is a pure function of (mesh, density, tree options, sequence,
// seed, k).
//
// Columns: index; u, v = barycentric coordinates of corners 1 and 2 of the
// sample's triangle (MeshSampleColumns::w holds corner 0's, and ::triangle
// the triangle's index in the loaded mesh); x, y, z on the flat triangle;
// optional normal (interpolated vertex normals when the mesh has them, else
// the face normal), density, and curve position = (rank of the triangle on
// the curve + area fraction along its own curve) / triangles, in [0, 1).
//
// Thread-safety: MeshSampler is immutable and thread-safe; a cursor is used
// by one thread at a time.
#ifndef SFCSAMPLER_MESH_MESH_SAMPLER_H_
#define SFCSAMPLER_MESH_MESH_SAMPLER_H_

#include <algorithm>
#include <array>
#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include "absl/status/statusor.h"
#include "core/region.h"
#include "core/sample_batch.h"
#include "core/sequence.h"
#include "mesh/mesh_curve_tree.h"

namespace sfc {

// The mesh-only columns, kept beside a SampleBatch row for row (SampleBatch
// itself is unchanged).
struct MeshSampleColumns {
  std::vector<uint32_t> triangle;  // index into TriangleMesh::triangles
  std::vector<double> w;           // barycentric coordinate of corner 0 (u + v + w = 1)

  size_t size() const { return triangle.size(); }
  void Clear() { triangle.clear(), w.clear(); }
};

// One sample, computed alone.
struct MeshSample {
  uint64_t index = 0;
  uint32_t triangle = 0;
  std::array<double, 3> bary{};  // corners 0, 1, 2
  Vec3 position;
  double curve_position = 0;
  size_t leaf = 0;
};

class MeshSampler {
 public:
  MeshSampler(std::shared_ptr<const MeshCurveTree> tree, Sequence sequence);

  const MeshCurveTree& tree() const { return *tree_; }
  const Sequence& sequence() const { return sequence_; }

  double MassCoordinate(uint64_t k) const { return sequence_.At(k) * tree_->total_mass(); }
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
  // First k in [0, count) whose mass coordinate is >= m (monotone sequences).
  uint64_t FirstIndexAtOrAbove(double m) const;
  // Sample k. REQUIRES: k < sequence().count().
  MeshSample At(uint64_t k) const;
  // Sample k's fraction of leaf l's mass, in [0, 1).
  double FractionInLeaf(double m, size_t l) const {
    const double begin = tree_->mass_begin(l);
    const double t = (m - begin) / (tree_->mass_ends()[l] - begin);
    if (!(t >= 0)) return 0;
    if (!(t < 1)) return 0x1.fffffffffffffp-1;  // the largest double below 1
    return t;
  }
  // Sample at mass coordinate m inside leaf l with cell `cell` (= LeafCell(l)).
  MeshSample AtMass(uint64_t k, double m, size_t l, const MeshCurveTree::Cell& cell) const;

 private:
  std::shared_ptr<const MeshCurveTree> tree_;
  Sequence sequence_;
  size_t last_positive_leaf_ = 0;
};

class MeshSampleCursor {
 public:
  // Samples with index in [begin, end) that lie in `region`, in curve order.
  // Errors (INVALID_ARGUMENT): begin > end, end > count, an empty or
  // degenerate region, or a parameter rectangle (a mesh has no parameter
  // square: use a 3D box). For monotone sequences (jittered, equal) the cost
  // is proportional to the samples emitted plus the triangles whose bounding
  // boxes meet the region; other sequences sort the range into curve order
  // first (O(n log n), n = end - begin). `threads` > 1 lets Next() fill large
  // batches of plain index ranges on the shared worker pool
  // (base/worker_pool.h); the samples do not change.
  static absl::StatusOr<std::unique_ptr<MeshSampleCursor>> Create(
      std::shared_ptr<const MeshSampler> sampler, uint64_t begin, uint64_t end,
      const Region& region, const SampleFields& fields, int threads = 1);

  // Appends up to `max` samples to `batch` (not cleared) and, when given, the
  // mesh columns to `mesh_columns`; returns how many; 0 once exhausted.
  // Errors: INVALID_ARGUMENT when the density is negative or not finite at a
  // sample (only when the density column is asked for).
  absl::StatusOr<size_t> Next(size_t max, SampleBatch* batch,
                              MeshSampleColumns* mesh_columns = nullptr);

 private:
  MeshSampleCursor(std::shared_ptr<const MeshSampler> sampler, Region region, SampleFields fields)
      : sampler_(std::move(sampler)), region_(region), fields_(fields) {}
  absl::Status Plan(uint64_t begin, uint64_t end);
  // Writes up to `max` samples into rows at, at + 1, ... of the batch's
  // columns (mesh_at, ... of the mesh columns), which hold them already
  // (Resize); returns how many.
  absl::StatusOr<size_t> Emit(size_t max, SampleBatch* batch, MeshSampleColumns* mesh_columns,
                              size_t at, size_t mesh_at);
  void Resize(size_t at, size_t mesh_at, size_t rows, SampleBatch* batch,
              MeshSampleColumns* mesh_columns) const;

  struct Segment {
    uint64_t begin, end;
  };
  const std::shared_ptr<const MeshSampler> sampler_;
  const Region region_;
  const SampleFields fields_;
  std::vector<Segment> segments_;  // monotone sequences: index ranges in curve order
  size_t segment_ = 0;
  uint64_t next_k_ = 0;
  std::vector<uint64_t> order_;    // other sequences: indices in curve order
  size_t order_pos_ = 0;
  bool use_order_ = false;
  int threads_ = 1;
  // Batches of at least this many samples of a plain range go to the pool.
  static constexpr uint64_t kParallelMin = 8192;
  size_t cached_leaf_ = SIZE_MAX;  // the last leaf decoded
  MeshCurveTree::Cell cached_cell_;
  std::vector<MeshCurveTree::Cell> chunk_cells_;  // the cells of one chunk of samples
};

}  // namespace sfc

#endif  // SFCSAMPLER_MESH_MESH_SAMPLER_H_
