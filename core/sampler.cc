#include "core/sampler.h"

#include <algorithm>
#include <cmath>
#include <functional>

#include "absl/strings/str_format.h"
#include "base/column_memory.h"
#include "base/status_macros.h"
#include "base/worker_pool.h"

namespace sfc {

Sampler::Sampler(std::shared_ptr<const CurveTree> tree, std::shared_ptr<const Surface> surface,
                 std::shared_ptr<const Density> density, Sequence sequence)
    : tree_(std::move(tree)),
      surface_(std::move(surface)),
      density_(std::move(density)),
      sequence_(sequence) {}

uint64_t Sampler::FirstIndexAtOrAbove(double m) const {
  return FirstIndexWhere(sequence_.count(), [&](uint64_t k) { return MassCoordinate(k) >= m; });
}

SampleCursor::SampleCursor(std::shared_ptr<const Sampler> sampler, Region region,
                           SampleFields fields)
    : sampler_(std::move(sampler)), region_(region), fields_(fields), walk_(sampler_->tree()) {}

absl::StatusOr<std::unique_ptr<SampleCursor>> SampleCursor::Create(
    std::shared_ptr<const Sampler> sampler, uint64_t begin, uint64_t end, const Region& region,
    const SampleFields& fields, int threads) {
  const uint64_t count = sampler->sequence().count();
  if (begin > end || end > count) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "the index range [%d, %d) is not inside the set of %d samples; it needs begin <= end <= "
        "count",
        begin, end, count));
  }
  RETURN_IF_ERROR(region.Validate());
  auto cursor = std::unique_ptr<SampleCursor>(new SampleCursor(std::move(sampler), region, fields));
  cursor->threads_ = std::max(1, threads);
  RETURN_IF_ERROR(cursor->PlanRegion(begin, end));
  return cursor;
}

absl::Status SampleCursor::PlanRegion(uint64_t begin, uint64_t end) {
  const Sampler& sampler = *sampler_;
  if (!sampler.sequence().monotone()) {
    // Index order is not curve order.
    const Sequence& sequence = sampler.sequence();
    order_ = IndicesInCurveOrder(
        begin, end, [&](uint64_t k) { return sampler.MassCoordinate(k); },
        [&](uint64_t k) { return sequence.InWindow(k); });
    use_order_ = true;
    return absl::OkStatus();
  }
  if (region_.kind == Region::Kind::kAll) {
    if (begin < end) segments_.push_back({begin, end});
    if (!segments_.empty()) next_k_ = segments_[0].begin;
    return absl::OkStatus();
  }

  const CurveTree& tree = sampler.tree();
  const Curve& curve = tree.curve();
  const Surface& surface = sampler.surface();
  const uint64_t count = sampler.sequence().count();

  // Adds the samples of leaves [a, b) (clipped to [begin, end)) as a segment.
  auto add_leaves = [&](size_t a, size_t b) {
    const uint64_t kb = a == 0 ? 0 : sampler.FirstIndexAtOrAbove(tree.mass_begin(a));
    const uint64_t ke = tree.mass_end(b - 1) >= tree.total_mass()
                            ? count
                            : sampler.FirstIndexAtOrAbove(tree.mass_end(b - 1));
    const uint64_t lo = std::max(kb, begin), hi = std::min(ke, end);
    if (lo >= hi) return;
    if (!segments_.empty() && segments_.back().end == lo) {
      segments_.back().end = hi;
    } else {
      segments_.push_back({lo, hi});
    }
  };

  // How a parameter cell's samples relate to the region. kUnknown: the
  // surface offers no bound, so every sample of the cell is tested.
  enum class Overlap { kNone, kPartial, kInside, kUnknown };
  // A sample's parameters are computed from its leaf's cell and may stray
  // from the cell [u0, u0 + h] computed here by a few ulp (cell sides 3^-k
  // are not exact in binary): cells are widened by this much.
  constexpr double kParameterSlack = 1e-12;
  // Parameter cell against the region. For a 3D box the cell's patch is
  // enclosed by Surface::Bound, a proven box, so a cell is skipped only when
  // none of its samples can lie in the region and taken whole only when all
  // of them do. Generate still tests every sample it is handed.
  auto overlap = [&](double u0, double v0, double h) -> Overlap {
    const double cu0 = std::max(0.0, u0 - kParameterSlack);
    const double cu1 = std::min(1.0, u0 + h + kParameterSlack);
    const double cv0 = std::max(0.0, v0 - kParameterSlack);
    const double cv1 = std::min(1.0, v0 + h + kParameterSlack);
    if (region_.kind == Region::Kind::kParameterRect) {
      if (cu0 > region_.u1 || cu1 < region_.u0 || cv0 > region_.v1 || cv1 < region_.v0) {
        return Overlap::kNone;
      }
      const bool inside =
          cu0 >= region_.u0 && cu1 <= region_.u1 && cv0 >= region_.v0 && cv1 <= region_.v1;
      return inside ? Overlap::kInside : Overlap::kPartial;
    }
    const std::optional<Box3> bound = surface.Bound(cu0, cu1, cv0, cv1);
    if (!bound) return Overlap::kUnknown;
    const Vec3& lo = bound->lo;
    const Vec3& hi = bound->hi;
    const Vec3& rl = region_.lo;
    const Vec3& rh = region_.hi;
    if (lo.x > rh.x || hi.x < rl.x || lo.y > rh.y || hi.y < rl.y || lo.z > rh.z || hi.z < rl.z) {
      return Overlap::kNone;
    }
    const bool inside = lo.x >= rl.x && hi.x <= rh.x && lo.y >= rl.y && hi.y <= rh.y &&
                        lo.z >= rl.z && hi.z <= rh.z;
    return inside ? Overlap::kInside : Overlap::kPartial;
  };

  // Walks the tree's cells in curve order, descending only where a cell
  // straddles the region's boundary (cost: the samples taken plus the cells
  // on the boundary, when the bounds are tight).
  std::function<absl::Status(int, uint64_t, uint64_t, uint64_t, int)> visit =
      [&](int depth, uint64_t start, uint64_t x, uint64_t y, int state) -> absl::Status {
    const size_t a = tree.LeafAt(start);
    const size_t b = tree.LeafAt(start + curve.Span(depth) - 1) + 1;
    const double h = 1.0 / curve.PowG(depth);
    const Overlap o = overlap(x * h, y * h, h);
    if (o == Overlap::kNone) return absl::OkStatus();
    if (o != Overlap::kPartial || b - a == 1) {
      add_leaves(a, b);
      return absl::OkStatus();
    }
    const int g = curve.grid();
    for (int c = 0; c < curve.arity(); ++c) {
      const Curve::Child& ch = curve.ChildOf(state, c);
      RETURN_IF_ERROR(visit(depth + 1, start + c * curve.Span(depth + 1), x * g + ch.dx,
                            y * g + ch.dy, ch.state));
    }
    return absl::OkStatus();
  };
  RETURN_IF_ERROR(visit(0, 0, 0, 0, Curve::kRootState));
  if (!segments_.empty()) next_k_ = segments_[0].begin;
  return absl::OkStatus();
}

absl::StatusOr<size_t> SampleCursor::Next(size_t max, SampleBatch* batch) {
  // Large runs inside one plain index range are split over threads.
  constexpr size_t kMinParallel = 8192;
  size_t produced = 0;
  while (produced < max) {
    // The next run: at most the samples still wanted, inside one segment. A
    // region keeps fewer than it is handed, so runs repeat until max are kept.
    size_t kept;
    if (use_order_) {
      if (order_pos_ >= order_.size()) break;
      const size_t n = std::min<size_t>(max - produced, order_.size() - order_pos_);
      ASSIGN_OR_RETURN(kept, Generate(0, order_.data() + order_pos_, n, batch));
      order_pos_ += n;
    } else {
      if (segment_ >= segments_.size()) break;
      const size_t n = std::min<uint64_t>(max - produced, segments_[segment_].end - next_k_);
      if (threads_ > 1 && region_.kind == Region::Kind::kAll && n >= kMinParallel) {
        RETURN_IF_ERROR(GenerateParallel(next_k_, n, batch));
        kept = n;
      } else {
        ASSIGN_OR_RETURN(kept, Generate(next_k_, nullptr, n, batch));
      }
      next_k_ += n;
      if (next_k_ >= segments_[segment_].end && ++segment_ < segments_.size()) {
        next_k_ = segments_[segment_].begin;
      }
    }
    produced += kept;
  }
  return produced;
}

SampleCursor::Rows SampleCursor::Rows::From(size_t offset) const {
  auto at = [offset](double* column) { return column == nullptr ? nullptr : column + offset; };
  return {index + offset, at(u),  at(v),  at(x),       at(y),
          at(z),          at(nx), at(ny), at(nz),      at(density),
          at(curve_position)};
}

SampleCursor::Rows SampleCursor::Grow(SampleBatch* batch, size_t n) const {
  const size_t s0 = batch->size(), rows = s0 + n;
  auto grow = [&](std::vector<double>* column, bool wanted) -> double* {
    if (!wanted) return nullptr;
    ResizeColumn(column, rows);
    return column->data() + s0;
  };
  ResizeColumn(&batch->index, rows);
  Rows out;
  out.index = batch->index.data() + s0;
  out.u = grow(&batch->u, true), out.v = grow(&batch->v, true);
  out.x = grow(&batch->x, true), out.y = grow(&batch->y, true), out.z = grow(&batch->z, true);
  out.nx = grow(&batch->nx, fields_.normal), out.ny = grow(&batch->ny, fields_.normal);
  out.nz = grow(&batch->nz, fields_.normal);
  out.density = grow(&batch->density, fields_.density);
  out.curve_position = grow(&batch->curve_position, fields_.curve_position);
  return out;
}

void SampleCursor::Truncate(SampleBatch* batch, size_t rows) const {
  batch->index.resize(rows);
  for (auto* column : {&batch->u, &batch->v, &batch->x, &batch->y, &batch->z}) column->resize(rows);
  if (fields_.normal) {
    for (auto* column : {&batch->nx, &batch->ny, &batch->nz}) column->resize(rows);
  }
  if (fields_.density) batch->density.resize(rows);
  if (fields_.curve_position) batch->curve_position.resize(rows);
}

absl::StatusOr<size_t> SampleCursor::Generate(uint64_t k0, const uint64_t* order, size_t n,
                                              SampleBatch* batch) {
  const size_t s0 = batch->size();
  const Rows out = Grow(batch, n);
  if (absl::Status st = Fill(k0, order, n, walk_, out); !st.ok()) {
    Truncate(batch, s0);
    return st;
  }
  if (region_.kind == Region::Kind::kAll) return n;
  // Keep the rows inside the region, in order.
  size_t kept = 0;
  for (size_t i = 0; i < n; ++i) {
    if (!region_.Contains(out.u[i], out.v[i], {out.x[i], out.y[i], out.z[i]})) continue;
    if (kept != i) {
      out.index[kept] = out.index[i];
      for (double* column : {out.u, out.v, out.x, out.y, out.z, out.nx, out.ny, out.nz,
                             out.density, out.curve_position}) {
        if (column != nullptr) column[kept] = column[i];
      }
    }
    ++kept;
  }
  Truncate(batch, s0 + kept);
  return kept;
}

absl::Status SampleCursor::GenerateParallel(uint64_t k0, size_t n, SampleBatch* batch) {
  // threads_ contiguous parts of the run, on the shared pool, each filling its
  // own rows of the grown columns; part 0 with the cursor's walk, the others
  // with their own. The walk is a pure function of the mass coordinate, so
  // the bytes are the same for any split.
  const size_t s0 = batch->size();
  const Rows out = Grow(batch, n);
  const int parts = threads_;
  std::vector<absl::Status> status(parts);
  auto bound = [&](int i) { return n * i / parts; };
  WorkerPool::Shared().ParallelFor(parts, [&](int i) {
    const size_t begin = bound(i), count = bound(i + 1) - begin;
    if (i == 0) {
      status[i] = Fill(k0, nullptr, count, walk_, out);
    } else {
      LeafWalk walk(sampler_->tree());
      status[i] = Fill(k0 + begin, nullptr, count, walk, out.From(begin));
    }
  });
  for (const absl::Status& st : status) {
    if (!st.ok()) {
      Truncate(batch, s0);
      return st;
    }
  }
  return absl::OkStatus();
}

absl::Status SampleCursor::Fill(uint64_t k0, const uint64_t* order, size_t n, LeafWalk& walk,
                                const Rows& out) const {
  const Sampler& sampler = *sampler_;
  const double total_mass = sampler.tree().total_mass();
  // Mass coordinates q_k S_M, in x until the points overwrite them.
  double* m = out.x;
  if (order == nullptr) {
    sampler.sequence().AtMany(k0, n, m);
    for (size_t i = 0; i < n; ++i) {
      m[i] *= total_mass;
      out.index[i] = k0 + i;
    }
  } else {
    for (size_t i = 0; i < n; ++i) {
      m[i] = sampler.MassCoordinate(order[i]);
      out.index[i] = order[i];
    }
  }
  walk.Place(m, n, out.u, out.v, out.curve_position);

  const Surface& surface = sampler.surface();
  const Density& density = sampler.density();
  auto not_finite = [&](size_t i) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "sample %d falls at (u,v) = (%.17g, %.17g), where the surface is not finite; fix the "
        "surface so it is defined everywhere on its box",
        out.index[i], out.u[i], out.v[i]));
  };
  const bool need_jet = fields_.normal || fields_.density;
  if (!need_jet) {
    // Positions alone: one call for the batch (the mass coordinates in x are spent).
    surface.Points(out.u, out.v, n, out.x, out.y, out.z);
    for (size_t i = 0; i < n; ++i) {
      if (!IsFinite(Vec3{out.x[i], out.y[i], out.z[i]})) return not_finite(i);
    }
    return absl::OkStatus();
  }
  const int jet_order = fields_.density && density.NeedsCurvature() ? 2 : 1;
  for (size_t i = 0; i < n; ++i) {
    const double u = out.u[i], v = out.v[i];
    const SurfaceJet jet = surface.Jet(u, v, jet_order);
    if (!IsFinite(jet.p)) return not_finite(i);
    out.x[i] = jet.p.x, out.y[i] = jet.p.y, out.z[i] = jet.p.z;
    const SurfaceGeometry geo = GeometryOf(jet);
    if (fields_.normal) {
      out.nx[i] = geo.normal.x, out.ny[i] = geo.normal.y, out.nz[i] = geo.normal.z;
    }
    if (fields_.density) {
      SurfacePoint point;
      point.u = u, point.v = v, point.p = jet.p, point.normal = geo.normal;
      point.gaussian_curvature = geo.gaussian_curvature;
      point.mean_curvature = geo.mean_curvature;
      out.density[i] = density.Value(point);
    }
  }
  return absl::OkStatus();
}

}  // namespace sfc
