#include "core/sampler.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <optional>

#include "absl/strings/str_format.h"
#include "base/status_macros.h"
#include "core/leaf_walk.h"

namespace sfc {
namespace {

// Whether the jet's derivatives up to `order` are finite.
bool DerivativesFinite(const SurfaceJet& jet, int order) {
  return IsFinite(jet.fu) && IsFinite(jet.fv) &&
         (order < 2 || (IsFinite(jet.fuu) && IsFinite(jet.fuv) && IsFinite(jet.fvv)));
}

// The jet whose normal and curvatures a sample at (u, v) reports: the jet
// there, or, where a derivative is infinite or NaN but the point is finite
// (a singular line of the parameterisation, such as the superellipsoid's
// |cos|^e at cos = 0, where 0 x inf meets in fu x fv), the first finite jet
// 2^(k - 53) from (u, v) towards the unit square's centre in both
// parameters, k = 0, 1, .., 40: the limit the normal and curvatures take at
// the line, to the parameter's rounding. The sample keeps its own point.
// Non-finite when none is (the surface is singular on a patch, not a line).
SurfaceJet ReportedJet(const Surface& surface, double u, double v, int order) {
  const SurfaceJet jet = surface.Jet(u, v, order);
  if (DerivativesFinite(jet, order) || !IsFinite(jet.p)) return jet;
  for (int k = 0; k <= 40; ++k) {
    const double step = std::ldexp(1.0, k - 53);
    const double nu = u < 0.5 ? u + step : u - step, nv = v < 0.5 ? v + step : v - step;
    SurfaceJet near = surface.Jet(nu, nv, order);
    if (DerivativesFinite(near, order)) {
      near.p = jet.p;
      return near;
    }
  }
  return jet;
}

// Places samples in their leaves (core/leaf_walk.h) and evaluates the surface
// there: points alone in one call for the batch, or jets for normals and
// densities.
class SurfaceFiller final : public SampleFiller {
 public:
  SurfaceFiller(const Sampler& sampler, const SampleFields& fields)
      : sampler_(sampler),
        fields_(fields),
        walk_(sampler.tree(), sampler.surface(), sampler.density()) {}

  absl::Status Fill(size_t n, const SampleRows& out) override;
  // Places each sample at its address through the sampler's TreeWarp.
  absl::Status FillAddressed(size_t n, const CurveAddress* at, const SampleRows& out) override;

 private:
  // Evaluates the surface at the rows' (u, v).
  absl::Status Evaluate(size_t n, const SampleRows& out);

  const Sampler& sampler_;
  const SampleFields fields_;
  LeafWalk walk_;
};

absl::Status SurfaceFiller::Fill(size_t n, const SampleRows& out) {
  walk_.Place(out.x, n, out.u, out.v, out.curve_position);
  return Evaluate(n, out);
}

absl::Status SurfaceFiller::FillAddressed(size_t n, const CurveAddress* at,
                                          const SampleRows& out) {
  sampler_.warp()->PlaceMany(n, at, out.u, out.v, out.curve_position);
  return Evaluate(n, out);
}

absl::Status SurfaceFiller::Evaluate(size_t n, const SampleRows& out) {
  const Surface& surface = sampler_.surface();
  const Density& density = sampler_.density();
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
    const SurfaceJet jet = ReportedJet(surface, u, v, jet_order);
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

}  // namespace

Sampler::Sampler(std::shared_ptr<const CurveTree> tree, std::shared_ptr<const Surface> surface,
                 std::shared_ptr<const Density> density, Sequence sequence)
    : CurveSamples(sequence, tree->total_mass()),
      tree_(std::move(tree)),
      surface_(std::move(surface)),
      density_(std::move(density)) {
  if (sequence.two_dimensional()) warp_ = std::make_unique<const TreeWarp>(*tree_);
}

void Sampler::WarpMany(size_t n, const double* a, const double* b, CurveAddress* out) const {
  warp_->LocateMany(n, a, b, out);
}

std::unique_ptr<SampleFiller> Sampler::NewFiller(const Region&, const SampleFields& fields) const {
  return std::make_unique<SurfaceFiller>(*this, fields);
}

absl::Status Sampler::PlanRegion(const Region& region, uint64_t begin, uint64_t end,
                                 std::vector<IndexSegment>* segments) const {
  const CurveTree& tree = *tree_;
  const Curve& curve = tree.curve();
  const Surface& surface = *surface_;

  // Adds the samples of leaves [a, b) (clipped to [begin, end)) as a segment.
  auto add_leaves = [&](size_t a, size_t b) {
    AddMassRange(tree.mass_begin(a), tree.mass_end(b - 1),
                 tree.mass_end(b - 1) >= tree.total_mass(), begin, end, segments);
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
    if (region.kind == Region::Kind::kParameterRect) {
      if (cu0 > region.u1 || cu1 < region.u0 || cv0 > region.v1 || cv1 < region.v0) {
        return Overlap::kNone;
      }
      const bool inside =
          cu0 >= region.u0 && cu1 <= region.u1 && cv0 >= region.v0 && cv1 <= region.v1;
      return inside ? Overlap::kInside : Overlap::kPartial;
    }
    const std::optional<Box3> bound = surface.Bound(cu0, cu1, cv0, cv1);
    if (!bound) return Overlap::kUnknown;
    const Vec3& lo = bound->lo;
    const Vec3& hi = bound->hi;
    const Vec3& rl = region.lo;
    const Vec3& rh = region.hi;
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
  return visit(0, 0, 0, 0, Curve::kRootState);
}

}  // namespace sfc
