#include "core/sampler.h"

#include <algorithm>
#include <cmath>
#include <functional>

#include "absl/strings/str_format.h"
#include "core/status_macros.h"
#include "core/worker_pool.h"

namespace sfc {

Sampler::Sampler(std::shared_ptr<const CurveTree> tree, std::shared_ptr<const Surface> surface,
                 std::shared_ptr<const Density> density, Sequence sequence)
    : tree_(std::move(tree)),
      surface_(std::move(surface)),
      density_(std::move(density)),
      sequence_(sequence) {
  last_positive_leaf_ = tree_->leaf_count() - 1;
  while (last_positive_leaf_ > 0 &&
         !(tree_->mass_end(last_positive_leaf_) > tree_->mass_begin(last_positive_leaf_))) {
    --last_positive_leaf_;
  }
}

size_t Sampler::LeafForMass(double m) const {
  const size_t l = tree_->FirstLeafEndingAbove(m);
  // q_k S_M can round up to S_M itself: it then belongs to the last leaf with mass.
  return l >= tree_->leaf_count() ? last_positive_leaf_ : l;
}

uint64_t Sampler::FirstIndexAtOrAbove(double m) const {
  return FirstIndexWhere(sequence_.count(), [&](uint64_t k) { return MassCoordinate(k) >= m; });
}

SampleCursor::SampleCursor(std::shared_ptr<const Sampler> sampler, Region region,
                           SampleFields fields)
    : sampler_(std::move(sampler)), region_(region), fields_(fields) {}

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
  // of them do. Emit still tests every sample it is handed.
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
  // Large batches inside one plain index range can be split over threads.
  constexpr size_t kMinParallel = 8192;
  if (threads_ > 1 && !use_order_ && region_.kind == Region::Kind::kAll && max >= kMinParallel &&
      segment_ < segments_.size() && segments_[segment_].end - next_k_ >= max) {
    const uint64_t k0 = next_k_;
    RETURN_IF_ERROR(EmitParallel(k0, k0 + max, batch));
    next_k_ += max;
    if (next_k_ >= segments_[segment_].end && ++segment_ < segments_.size()) {
      next_k_ = segments_[segment_].begin;
    }
    return max;
  }
  size_t produced = 0;
  while (produced < max) {
    uint64_t k;
    if (use_order_) {
      if (order_pos_ >= order_.size()) break;
      k = order_[order_pos_++];
    } else {
      if (segment_ >= segments_.size()) break;
      k = next_k_++;
      if (next_k_ >= segments_[segment_].end && ++segment_ < segments_.size()) {
        next_k_ = segments_[segment_].begin;
      }
    }
    bool kept = false;
    RETURN_IF_ERROR(Emit(k, cache_, batch, &kept));
    produced += kept;
  }
  return produced;
}

absl::Status SampleCursor::EmitParallel(uint64_t k0, uint64_t k1, SampleBatch* batch) {
  // threads_ contiguous parts of [k0, k1), on the shared pool; part 0 goes
  // straight into `batch` with the cursor's own leaf cache, the others into
  // their own batches, appended in order: the same samples for any split.
  const int n = threads_;
  std::vector<SampleBatch> parts(n - 1);
  std::vector<absl::Status> status(n);
  auto bound = [&](int i) { return k0 + (k1 - k0) * i / n; };
  WorkerPool::Shared().ParallelFor(n, [&](int i) {
    LeafCache local;
    LeafCache& cache = i == 0 ? cache_ : local;
    SampleBatch* out = i == 0 ? batch : &parts[i - 1];
    bool kept;
    for (uint64_t k = bound(i); k < bound(i + 1) && status[i].ok(); ++k) {
      status[i] = Emit(k, cache, out, &kept);
    }
  });
  for (const absl::Status& st : status) RETURN_IF_ERROR(st);
  for (const SampleBatch& part : parts) batch->Append(part);
  return absl::OkStatus();
}

absl::Status SampleCursor::Emit(uint64_t k, LeafCache& cache, SampleBatch* batch, bool* kept) const {
  const Sampler& sampler = *sampler_;
  const CurveTree& tree = sampler.tree();
  const Curve& curve = tree.curve();
  const double m = sampler.MassCoordinate(k);

  // Consecutive samples fall in the same or a nearby later leaf: gallop
  // forward from the last one before falling back to a full binary search.
  const size_t leaves = tree.leaf_count();
  size_t l = SIZE_MAX;
  if (cache.leaf != SIZE_MAX && m >= tree.mass_begin(cache.leaf)) {
    size_t lo = cache.leaf, step = 1, hi = lo;
    while (hi < leaves && tree.mass_end(hi) <= m) {
      lo = hi + 1;
      hi = lo + step;
      step *= 2;
    }
    hi = std::min(hi, leaves);
    l = tree.FirstLeafEndingAbove(m, lo);
    if (l > hi || l >= leaves) l = SIZE_MAX;
  }
  if (l == SIZE_MAX) l = sampler.LeafForMass(m);
  const double begin_mass = tree.mass_begin(l);
  const double leaf_mass = tree.mass_end(l) - begin_mass;
  if (l != cache.leaf) {
    cache.cell = tree.LeafCell(l);
    cache.leaf = l;
    // Samples' worth at the tree's grade, not the sequence's count: a
    // progressive set extended on the same tree keeps its prefix.
    cache.samples = leaf_mass / tree.total_mass() * std::ldexp(1.0, tree.grade());
    cache.stack.clear();
    cache.stack.push_back({0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 1.0, cache.cell.state});
  }
  const double t = std::clamp((m - begin_mass) / leaf_mass, 0.0, 1.0);

  // Model descent: pop to the deepest level holding t, then descend while the
  // sub-cell carries a noticeable part of a sample.
  auto& stack = cache.stack;
  while (stack.size() > 1 && !(t >= stack.back().t0 && t < stack.back().t1)) stack.pop_back();
  const LeafModel& model = tree.leaf_model(l);
  const LeafModel::Kind kind = tree.leaf_model_kind(l);
  const int g = curve.grid(), w = curve.arity();
  while (static_cast<int>(stack.size()) <= kMaxModelLevels &&
         (stack.back().t1 - stack.back().t0) * cache.samples >= kNegligibleSamples) {
    Level& top = stack.back();
    if (top.children == 0) {
      // The children's t bounds from the model's exact integrals, once per level.
      double by_grid[9], share[9], sum = 0;
      SubSquareIntegrals(model, kind, g, top.x0, top.y0, top.side, by_grid);
      for (int c = 0; c < w; ++c) {
        const Curve::Child& ch = curve.ChildOf(top.state, c);
        share[c] = std::max(0.0, by_grid[ch.dx * g + ch.dy]);
        sum += share[c];
      }
      if (!(sum > 0)) break;  // the model vanishes here: pure curve bits
      double acc = 0;
      for (int c = 0; c < w; ++c) {
        acc += share[c];
        top.bounds[c] = c + 1 == w ? top.t1 : top.t0 + (top.t1 - top.t0) * (acc / sum);
      }
      top.children = w;
    }
    double t0 = top.t0;
    int c = 0;
    for (; c < w; ++c) {
      const double t1 = top.bounds[c];
      if (t < t1 && t1 > t0) {
        const Curve::Child& ch = curve.ChildOf(top.state, c);
        const double side = top.side / g, span = top.span / w;
        const Level child{t0, t1, top.x0 + ch.dx * side, top.y0 + ch.dy * side, side,
                          top.pos + c * span, span, ch.state};
        stack.push_back(child);
        break;
      }
      t0 = t1;
    }
    if (c == w) break;  // rounding left t past the last child: stay here
  }
  const Level& at = stack.back();
  const double tr = at.t1 > at.t0 ? std::clamp((t - at.t0) / (at.t1 - at.t0), 0.0, 1.0) : 0.0;

  // Analytic continuation: follow the rest of t down the sub-cell's own curve.
  const int levels = curve.continuation_levels();
  const uint64_t scale = curve.PowW(levels);
  const uint64_t digits = std::min(static_cast<uint64_t>(tr * static_cast<double>(scale)), scale - 1);
  uint64_t cx, cy;
  int state = at.state;
  curve.Descend(digits, levels, &cx, &cy, &state);
  const double cell = at.side / curve.PowG(levels);
  const double u = cache.cell.u0 + (at.x0 + (static_cast<double>(cx) + 0.5) * cell) * cache.cell.size;
  const double v = cache.cell.v0 + (at.y0 + (static_cast<double>(cy) + 0.5) * cell) * cache.cell.size;

  const bool need_jet = fields_.normal || fields_.density;
  SurfaceJet jet;
  if (need_jet) {
    jet = sampler.surface().Jet(u, v, fields_.density && sampler.density().NeedsCurvature() ? 2 : 1);
  } else {
    jet.p = sampler.surface().Point(u, v);
  }
  if (!IsFinite(jet.p)) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "sample %d falls at (u,v) = (%.17g, %.17g), where the surface is not finite; fix the "
        "surface so it is defined everywhere on its box",
        k, u, v));
  }
  *kept = region_.Contains(u, v, jet.p);
  if (!*kept) return absl::OkStatus();

  batch->index.push_back(k);
  batch->u.push_back(u);
  batch->v.push_back(v);
  batch->x.push_back(jet.p.x);
  batch->y.push_back(jet.p.y);
  batch->z.push_back(jet.p.z);
  if (need_jet) {
    const SurfaceGeometry geo = GeometryOf(jet);
    if (fields_.normal) {
      batch->nx.push_back(geo.normal.x);
      batch->ny.push_back(geo.normal.y);
      batch->nz.push_back(geo.normal.z);
    }
    if (fields_.density) {
      SurfacePoint point;
      point.u = u, point.v = v, point.p = jet.p, point.normal = geo.normal;
      point.gaussian_curvature = geo.gaussian_curvature;
      point.mean_curvature = geo.mean_curvature;
      batch->density.push_back(sampler.density().Value(point));
    }
  }
  if (fields_.curve_position) {
    const double span = static_cast<double>(tree.leaf_end(l) - tree.leaf_start(l));
    const double pos = at.pos + tr * at.span;
    batch->curve_position.push_back((static_cast<double>(tree.leaf_start(l)) + pos * span) /
                                    static_cast<double>(curve.Span(0)));
  }
  return absl::OkStatus();
}

}  // namespace sfc
