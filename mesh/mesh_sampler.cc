#include "mesh/mesh_sampler.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_format.h"
#include "base/column_memory.h"
#include "base/status_macros.h"
#include "base/worker_pool.h"

namespace sfc {

MeshSampler::MeshSampler(std::shared_ptr<const MeshCurveTree> tree, Sequence sequence)
    : tree_(std::move(tree)), sequence_(sequence) {
  last_positive_leaf_ = tree_->leaf_count() - 1;
  while (last_positive_leaf_ > 0 &&
         !(tree_->mass_ends()[last_positive_leaf_] > tree_->mass_begin(last_positive_leaf_))) {
    --last_positive_leaf_;
  }
}

size_t MeshSampler::LeafForMass(double m) const {
  const auto& ends = tree_->mass_ends();
  const size_t l = static_cast<size_t>(std::upper_bound(ends.begin(), ends.end(), m) - ends.begin());
  // q_k S_M can round up to S_M itself: it then belongs to the last leaf with mass.
  return l >= ends.size() ? last_positive_leaf_ : l;
}

uint64_t MeshSampler::FirstIndexAtOrAbove(double m) const {
  return FirstIndexWhere(sequence_.count(), [&](uint64_t k) { return MassCoordinate(k) >= m; });
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

absl::StatusOr<std::unique_ptr<MeshSampleCursor>> MeshSampleCursor::Create(
    std::shared_ptr<const MeshSampler> sampler, uint64_t begin, uint64_t end,
    const Region& region, const SampleFields& fields, int threads) {
  const uint64_t count = sampler->sequence().count();
  if (begin > end || end > count) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "the index range [%d, %d) is not inside the set of %d samples; it needs begin <= end <= "
        "count",
        begin, end, count));
  }
  if (region.kind == Region::Kind::kParameterRect) {
    return absl::InvalidArgumentError(
        "a mesh has no parameter square, so a parameter rectangle (uv:) selects nothing; give a "
        "3D box (box:x0,y0,z0,x1,y1,z1)");
  }
  RETURN_IF_ERROR(region.Validate());
  auto cursor =
      std::unique_ptr<MeshSampleCursor>(new MeshSampleCursor(std::move(sampler), region, fields));
  cursor->threads_ = std::max(1, threads);
  RETURN_IF_ERROR(cursor->Plan(begin, end));
  return cursor;
}

absl::Status MeshSampleCursor::Plan(uint64_t begin, uint64_t end) {
  const MeshSampler& sampler = *sampler_;
  const MeshCurveTree& tree = sampler.tree();
  if (!sampler.sequence().monotone()) {
    // Index order is not curve order.
    order_ = IndicesInCurveOrder(
        begin, end, [&](uint64_t k) { return sampler.MassCoordinate(k); },
        [](uint64_t) { return true; });
    use_order_ = true;
    return absl::OkStatus();
  }
  if (region_.kind == Region::Kind::kAll) {
    segments_.push_back({begin, end});
  } else {
    // Only the runs of triangles whose boxes meet the region: their samples
    // are the indices whose mass coordinates fall in the runs' mass intervals.
    std::vector<std::pair<size_t, size_t>> runs;
    tree.RanksMeetingBox(region_.lo, region_.hi, &runs);
    const uint64_t count = sampler.sequence().count();
    for (const auto& [a, b] : runs) {
      const uint64_t k0 = sampler.FirstIndexAtOrAbove(tree.mass_begin(tree.first_leaf(a)));
      // The run that ends the curve also takes q_k S_M rounded up to S_M.
      const uint64_t k1 = b == tree.triangle_count()
                              ? count
                              : sampler.FirstIndexAtOrAbove(tree.mass_begin(tree.first_leaf(b)));
      const uint64_t lo = std::max(k0, begin), hi = std::min(k1, end);
      if (lo < hi) segments_.push_back({lo, hi});
    }
  }
  if (!segments_.empty()) next_k_ = segments_[0].begin;
  return absl::OkStatus();
}

// The columns this cursor fills, sized to `rows` past their rows before this
// call (`at`, and `mesh_at` for the mesh columns), growing or shrinking.
void MeshSampleCursor::Resize(size_t at, size_t mesh_at, size_t rows, SampleBatch* batch,
                              MeshSampleColumns* mesh_columns) const {
  const size_t mesh_rows = mesh_at + rows;
  rows += at;
  ResizeColumn(&batch->index, rows);
  for (auto* column : {&batch->u, &batch->v, &batch->x, &batch->y, &batch->z}) {
    ResizeColumn(column, rows);
  }
  if (fields_.normal) {
    for (auto* column : {&batch->nx, &batch->ny, &batch->nz}) ResizeColumn(column, rows);
  }
  if (fields_.density) ResizeColumn(&batch->density, rows);
  if (fields_.curve_position) ResizeColumn(&batch->curve_position, rows);
  if (mesh_columns != nullptr) {
    ResizeColumn(&mesh_columns->triangle, mesh_rows);
    ResizeColumn(&mesh_columns->w, mesh_rows);
  }
}

absl::StatusOr<size_t> MeshSampleCursor::Next(size_t max, SampleBatch* batch,
                                              MeshSampleColumns* mesh_columns) {
  const size_t at = batch->size();
  const size_t mesh_at = mesh_columns != nullptr ? mesh_columns->size() : 0;
  // At most the indices left.
  uint64_t left = use_order_ ? order_.size() - order_pos_ : 0;
  if (!use_order_) {
    for (size_t i = segment_; i < segments_.size(); ++i) {
      left += segments_[i].end -
              (i == segment_ ? std::max(next_k_, segments_[i].begin) : segments_[i].begin);
    }
  }
  const size_t want = static_cast<size_t>(std::min<uint64_t>(left, max));
  Resize(at, mesh_at, want, batch, mesh_columns);  // written in place, then trimmed

  // A large stretch of a plain index range goes to the shared pool in
  // contiguous parts, each drawn by a cursor of its own straight into its
  // rows of the columns (a sample is a pure function of k, so the parts are
  // the samples one cursor would draw).
  if (threads_ > 1 && !use_order_ && region_.kind == Region::Kind::kAll &&
      segment_ < segments_.size() && want >= kParallelMin &&
      segments_[segment_].end - next_k_ >= kParallelMin) {
    const uint64_t k0 = next_k_, k1 = k0 + std::min<uint64_t>(want, segments_[segment_].end - k0);
    const int n = threads_;
    std::vector<absl::Status> status(n);
    WorkerPool::Shared().ParallelFor(n, [&](int i) {
      const uint64_t a = k0 + (k1 - k0) * i / n, b = k0 + (k1 - k0) * (i + 1) / n;
      MeshSampleCursor part(sampler_, region_, fields_);
      part.segments_.push_back({a, b});
      part.next_k_ = a;
      status[i] = part.Emit(b - a, batch, mesh_columns, at + (a - k0), mesh_at + (a - k0)).status();
    });
    for (const absl::Status& st : status) RETURN_IF_ERROR(st);
    next_k_ = k1;
    if (next_k_ >= segments_[segment_].end && ++segment_ < segments_.size()) {
      next_k_ = segments_[segment_].begin;
    }
    cached_leaf_ = SIZE_MAX;
    Resize(at, mesh_at, k1 - k0, batch, mesh_columns);
    return static_cast<size_t>(k1 - k0);
  }
  auto emitted = Emit(want, batch, mesh_columns, at, mesh_at);
  Resize(at, mesh_at, emitted.ok() ? *emitted : 0, batch, mesh_columns);
  return emitted;
}

absl::StatusOr<size_t> MeshSampleCursor::Emit(size_t max, SampleBatch* batch,
                                              MeshSampleColumns* mesh_columns, size_t at,
                                              size_t mesh_at) {
  const MeshSampler& sampler = *sampler_;
  const MeshCurveTree& tree = sampler.tree();
  const MeshSurface& surface = tree.surface();
  const auto& ends = tree.mass_ends();
  // Samples go in chunks: first their leaves and fractions, then their
  // descents together (MeshCurveTree::DescendMany), then the columns.
  constexpr size_t kChunk = 32;
  uint64_t ks[kChunk];
  double ts[kChunk], area_positions[kChunk];
  const MeshCurveTree::Cell* cells[kChunk];
  std::array<double, 3> barys[kChunk];
  chunk_cells_.reserve(kChunk + 1);  // pointers into it stay valid for a chunk
  const double triangles = static_cast<double>(tree.triangle_count());
  const Sequence& sequence = sampler.sequence();
  const double total = tree.total_mass();
  size_t emitted = 0;
  bool exhausted = false;
  while (emitted < max && !exhausted) {
    chunk_cells_.clear();
    if (cached_leaf_ != SIZE_MAX) chunk_cells_.push_back(cached_cell_);
    const size_t want = std::min(kChunk, max - emitted);
    size_t n = 0;
    double ms[kChunk];
    if (use_order_) {
      while (n < want && order_pos_ < order_.size()) {
        ks[n] = order_[order_pos_++];
        ms[n] = sampler.MassCoordinate(ks[n]);
        ++n;
      }
      exhausted = n < want;
    } else {
      while (segment_ < segments_.size() && next_k_ >= segments_[segment_].end) {
        if (++segment_ < segments_.size()) next_k_ = segments_[segment_].begin;
      }
      if (segment_ < segments_.size()) {
        // A run of consecutive indices inside one segment: their q_k in one call.
        n = static_cast<size_t>(std::min<uint64_t>(want, segments_[segment_].end - next_k_));
        sequence.AtMany(next_k_, n, ms);
        for (size_t i = 0; i < n; ++i) ks[i] = next_k_ + i, ms[i] *= total;
        next_k_ += n;
      } else {
        exhausted = true;
      }
    }
    for (size_t i = 0; i < n; ++i) {
      const double m = ms[i];
      if (cached_leaf_ == SIZE_MAX || !(m >= tree.mass_begin(cached_leaf_) && m < ends[cached_leaf_])) {
        const size_t l = cached_leaf_ != SIZE_MAX && m >= ends[cached_leaf_]
                             ? sampler.LeafForMassAfter(cached_leaf_, m)
                             : sampler.LeafForMass(m);
        if (l != cached_leaf_) {
          cached_leaf_ = l;
          cached_cell_ = tree.LeafCell(l);
          chunk_cells_.push_back(cached_cell_);
        }
      }
      ts[i] = sampler.FractionInLeaf(m, cached_leaf_);
      cells[i] = &chunk_cells_.back();
    }
    MeshCurveTree::DescendMany(n, cells, ts, barys, area_positions);
    for (size_t i = 0; i < n; ++i) {
      const uint32_t triangle = cells[i]->triangle;
      const std::array<double, 3>& bary = barys[i];
      const Vec3 position = surface.Point(triangle, bary);
      if (!region_.Contains(0, 0, position)) continue;
      const uint64_t k = ks[i];
      const size_t row = at + emitted;
      batch->index[row] = k;
      batch->u[row] = bary[1];
      batch->v[row] = bary[2];
      batch->x[row] = position.x;
      batch->y[row] = position.y;
      batch->z[row] = position.z;
      if (fields_.normal) {
        const Vec3 nrm = surface.Normal(triangle, bary);
        batch->nx[row] = nrm.x;
        batch->ny[row] = nrm.y;
        batch->nz[row] = nrm.z;
      }
      if (fields_.density) {
        const double d = tree.density().uniform()
                             ? 1.0
                             : tree.density().Evaluate(surface.Attributes(triangle, bary));
        if (!std::isfinite(d) || d < 0) {
          return absl::InvalidArgumentError(absl::StrFormat(
              "the density '%s' is %g at sample %d (%g, %g, %g); it must be finite and >= 0",
              tree.density().spec(), d, k, position.x, position.y, position.z));
        }
        batch->density[row] = d;
      }
      if (fields_.curve_position) {
        batch->curve_position[row] = (cells[i]->rank + area_positions[i]) / triangles;
      }
      if (mesh_columns != nullptr) {
        mesh_columns->triangle[mesh_at + emitted] = triangle;
        mesh_columns->w[mesh_at + emitted] = bary[0];
      }
      ++emitted;
    }
  }
  return emitted;
}

}  // namespace sfc
