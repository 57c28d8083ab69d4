#include "mesh/mesh_sampler.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "absl/strings/str_format.h"
#include "base/status_macros.h"

namespace sfc {
namespace {

// Places samples on their triangles: their leaves and fractions first, then
// their descents together in chunks (MeshCurveTree::DescendMany), then the
// columns. Remembers the last leaf decoded, as samples and leaves advance
// together.
class MeshFiller final : public SampleFiller {
 public:
  MeshFiller(const MeshSampler& sampler, const Region& region, const SampleFields& fields)
      : sampler_(sampler), region_(region), fields_(fields) {
    chunk_cells_.reserve(kChunk + 1);  // pointers into it stay valid for a chunk
  }

  absl::Status Fill(size_t n, const SampleRows& out) override {
    for (size_t i = 0; i < n; i += kChunk) {
      RETURN_IF_ERROR(FillChunk(std::min(kChunk, n - i), out.From(i)));
    }
    return absl::OkStatus();
  }

  // Places each sample at its address (MeshWarp::Locate's): its leaf's cell
  // (decoded once for a run of samples in one leaf, as addresses come sorted)
  // and the sub-cell the address's digits choose, a chunk at a time.
  absl::Status FillAddressed(size_t n, const CurveAddress* at, const SampleRows& out) override {
    const MeshCurveTree& tree = sampler_.tree();
    for (size_t i0 = 0; i0 < n; i0 += kChunk) {
      const size_t m = std::min(kChunk, n - i0);
      const MeshCurveTree::Cell* cells[kChunk];
      uint64_t paths[kChunk];
      std::array<double, 3> barys[kChunk];
      double area_positions[kChunk];
      chunk_cells_.clear();
      if (cached_leaf_ != SIZE_MAX) chunk_cells_.push_back(cached_cell_);
      for (size_t i = 0; i < m; ++i) {
        const CurveAddress& a = at[i0 + i];
        if (a.leaf != cached_leaf_) {
          cached_leaf_ = a.leaf;
          cached_cell_ = tree.LeafCell(a.leaf);
          chunk_cells_.push_back(cached_cell_);
        }
        cells[i] = &chunk_cells_.back();
        paths[i] = a.digits;
      }
      MeshCurveTree::DescendPaths(m, cells, paths, barys, area_positions);
      RETURN_IF_ERROR(WriteColumns(m, cells, barys, area_positions, out.From(i0)));
    }
    return absl::OkStatus();
  }

 private:
  static constexpr size_t kChunk = 32;
  // Fill for n <= kChunk rows.
  absl::Status FillChunk(size_t n, const SampleRows& out);
  // The columns of n placed samples: sample i in cells[i] at barys[i].
  absl::Status WriteColumns(size_t n, const MeshCurveTree::Cell* const* cells,
                            const std::array<double, 3>* barys, const double* area_positions,
                            const SampleRows& out);

  const MeshSampler& sampler_;
  const Region region_;
  const SampleFields fields_;
  size_t cached_leaf_ = SIZE_MAX;  // the last leaf decoded
  MeshCurveTree::Cell cached_cell_;
  std::vector<MeshCurveTree::Cell> chunk_cells_;  // the cells of one chunk of samples
};

absl::Status MeshFiller::FillChunk(size_t n, const SampleRows& out) {
  const MeshCurveTree& tree = sampler_.tree();
  const auto& ends = tree.mass_ends();
  double ts[kChunk], area_positions[kChunk];
  const MeshCurveTree::Cell* cells[kChunk];
  std::array<double, 3> barys[kChunk];
  chunk_cells_.clear();
  if (cached_leaf_ != SIZE_MAX) chunk_cells_.push_back(cached_cell_);
  for (size_t i = 0; i < n; ++i) {
    const double m = out.x[i];
    if (cached_leaf_ == SIZE_MAX ||
        !(m >= tree.mass_begin(cached_leaf_) && m < ends[cached_leaf_])) {
      const size_t l = cached_leaf_ != SIZE_MAX && m >= ends[cached_leaf_]
                           ? sampler_.LeafForMassAfter(cached_leaf_, m)
                           : sampler_.LeafForMass(m);
      if (l != cached_leaf_) {
        cached_leaf_ = l;
        cached_cell_ = tree.LeafCell(l);
        chunk_cells_.push_back(cached_cell_);
      }
    }
    ts[i] = sampler_.FractionInLeaf(m, cached_leaf_);
    cells[i] = &chunk_cells_.back();
  }
  MeshCurveTree::DescendMany(n, cells, ts, barys, area_positions);
  return WriteColumns(n, cells, barys, area_positions, out);
}

absl::Status MeshFiller::WriteColumns(size_t n, const MeshCurveTree::Cell* const* cells,
                                      const std::array<double, 3>* barys,
                                      const double* area_positions, const SampleRows& out) {
  const MeshCurveTree& tree = sampler_.tree();
  const MeshSurface& surface = tree.surface();
  const double triangles = static_cast<double>(tree.triangle_count());
  for (size_t i = 0; i < n; ++i) {
    const uint32_t triangle = cells[i]->triangle;
    const std::array<double, 3>& bary = barys[i];
    const Vec3 position = surface.Point(triangle, bary);
    out.u[i] = bary[1];
    out.v[i] = bary[2];
    out.x[i] = position.x;
    out.y[i] = position.y;
    out.z[i] = position.z;
    if (out.triangle != nullptr) out.triangle[i] = triangle;
    if (!region_.Contains(0, 0, position)) continue;  // dropped by the cursor
    if (fields_.normal) {
      const Vec3 nrm = surface.Normal(triangle, bary);
      out.nx[i] = nrm.x;
      out.ny[i] = nrm.y;
      out.nz[i] = nrm.z;
    }
    if (fields_.density) {
      const double d = tree.density().uniform()
                           ? 1.0
                           : tree.density().Evaluate(surface.Attributes(triangle, bary));
      if (!std::isfinite(d) || d < 0) {
        return absl::InvalidArgumentError(absl::StrFormat(
            "the density '%s' is %g at sample %d (%g, %g, %g); it must be finite and >= 0",
            tree.density().spec(), d, out.index[i], position.x, position.y, position.z));
      }
      out.density[i] = d;
    }
    if (fields_.curve_position) {
      out.curve_position[i] = CurvePosition(cells[i]->rank + area_positions[i], triangles);
    }
  }
  return absl::OkStatus();
}

}  // namespace

MeshSampler::MeshSampler(std::shared_ptr<const MeshCurveTree> tree, Sequence sequence)
    : CurveSamples(sequence, tree->total_mass()), tree_(std::move(tree)) {
  last_positive_leaf_ = tree_->leaf_count() - 1;
  while (last_positive_leaf_ > 0 &&
         !(tree_->mass_ends()[last_positive_leaf_] > tree_->mass_begin(last_positive_leaf_))) {
    --last_positive_leaf_;
  }
  if (sequence.two_dimensional()) warp_ = std::make_unique<const MeshWarp>(*tree_);
}

void MeshSampler::WarpMany(size_t n, const double* a, const double* b, CurveAddress* out) const {
  warp_->LocateMany(n, a, b, out);
}

size_t MeshSampler::LeafForMass(double m) const {
  const auto& ends = tree_->mass_ends();
  const size_t l =
      static_cast<size_t>(std::upper_bound(ends.begin(), ends.end(), m) - ends.begin());
  // q_k S_M can round up to S_M itself: it then belongs to the last leaf with mass.
  return l >= ends.size() ? last_positive_leaf_ : l;
}

MeshSample MeshSampler::AtMass(uint64_t k, double m, size_t l,
                               const MeshCurveTree::Cell& cell) const {
  const double t = FractionInLeaf(m, l);
  MeshSample s;
  s.index = k;
  s.leaf = l;
  s.triangle = cell.triangle;
  double area_position;
  MeshCurveTree::Descend(cell, t, &s.bary, &area_position);
  s.position = tree_->surface().Point(cell.triangle, s.bary);
  s.curve_position = (cell.rank + area_position) / static_cast<double>(tree_->triangle_count());
  return s;
}

MeshSample MeshSampler::At(uint64_t k) const {
  const double m = MassCoordinate(k);
  const size_t l = LeafForMass(m);
  return AtMass(k, m, l, tree_->LeafCell(l));
}

absl::Status MeshSampler::AcceptsRegion(const Region& region) const {
  if (region.kind != Region::Kind::kParameterRect) return absl::OkStatus();
  return absl::InvalidArgumentError(
      "a mesh has no parameter square, so a parameter rectangle (uv:) selects nothing; give a "
      "3D box (box:x0,y0,z0,x1,y1,z1)");
}

absl::Status MeshSampler::PlanRegion(const Region& region, uint64_t begin, uint64_t end,
                                     std::vector<IndexSegment>* segments) const {
  // Only the runs of triangles whose boxes meet the region: their samples are
  // the indices whose mass coordinates fall in the runs' mass intervals.
  const MeshCurveTree& tree = *tree_;
  std::vector<std::pair<size_t, size_t>> runs;
  tree.RanksMeetingBox(region.lo, region.hi, &runs);
  for (const auto& [a, b] : runs) {
    // The run that ends the curve also takes q_k S_M rounded up to S_M.
    const bool through_end = b == tree.triangle_count();
    AddMassRange(tree.mass_begin(tree.first_leaf(a)),
                 through_end ? tree.total_mass() : tree.mass_begin(tree.first_leaf(b)),
                 through_end, begin, end, segments);
  }
  return absl::OkStatus();
}

std::unique_ptr<SampleFiller> MeshSampler::NewFiller(const Region& region,
                                                     const SampleFields& fields) const {
  return std::make_unique<MeshFiller>(*this, region, fields);
}

}  // namespace sfc
