#include "core/area_estimator.h"

#include <cmath>

#include "absl/strings/str_format.h"
#include "base/status_macros.h"

namespace sfc {
namespace {

absl::StatusOr<Vec3> FinitePoint(const Surface& surface, double u, double v) {
  const Vec3 p = surface.Point(u, v);
  if (!IsFinite(p)) return SurfaceNotFiniteError(u, v);
  return p;
}

double TriangleArea(const Vec3& a, const Vec3& b, const Vec3& c) {
  return 0.5 * Norm(Cross(b - a, c - a));
}

}  // namespace

namespace {

// delta and the area element from a jet at (u, v), checked.
absl::StatusOr<DensityAt> DensityFromJet(const SurfaceJet& jet, const Density& density, double u,
                                         double v) {
  if (!IsFinite(jet.p)) return SurfaceNotFiniteError(u, v);
  double area_element;
  const SurfacePoint point = PointFromJet(jet, u, v, density.NeedsCurvature(), &area_element);
  DensityAt out;
  out.p = jet.p;
  out.delta = density.Value(point);
  out.area_element = area_element;
  RETURN_IF_ERROR(CheckDensityValue(out.delta, u, v));
  // A derivative that overflows (a singular parameterisation) gives an infinite
  // area element; the point itself is finite, so treat the element as unusable.
  if (!std::isfinite(out.area_element)) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "the surface's area element is not finite at (u,v) = (%.17g, %.17g); the parameterisation "
        "is singular there (consider a reparameterisation, paper Sect. 5.3)",
        u, v));
  }
  return out;
}

}  // namespace

SurfacePoint PointFromJet(const SurfaceJet& jet, double u, double v, bool curvature,
                          double* area_element) {
  SurfacePoint point;
  point.u = u;
  point.v = v;
  point.p = jet.p;
  if (curvature) {
    const SurfaceGeometry geo = GeometryOf(jet);
    point.normal = geo.normal;
    point.gaussian_curvature = geo.gaussian_curvature;
    point.mean_curvature = geo.mean_curvature;
    *area_element = geo.area_element;
  } else {
    *area_element = Norm(Cross(jet.fu, jet.fv));
  }
  return point;
}

namespace {

// MassDensityGrid with room for the grid's jets in `jets`.
void MassDensityGridIn(const Surface& surface, const Density& density, const double* us, int nu,
                       const double* vs, int nv, double* out, SurfaceJet* jets) {
  const bool curvature = density.NeedsCurvature();
  surface.JetGrid(us, nu, vs, nv, curvature ? 2 : 1, jets);
  for (int i = 0; i < nu; ++i) {
    for (int j = 0; j < nv; ++j) {
      const SurfaceJet& jet = jets[static_cast<size_t>(i) * nv + j];
      double& m = out[static_cast<size_t>(i) * nv + j];
      m = INFINITY;
      if (!IsFinite(jet.p)) continue;
      double area;
      const SurfacePoint point = PointFromJet(jet, us[i], vs[j], curvature, &area);
      if (!std::isfinite(area)) continue;
      const double delta = density.Value(point);
      if (std::isfinite(delta)) m = delta * area;
    }
  }
}

}  // namespace

void MassDensityGrid(const Surface& surface, const Density& density, const double* us, int nu,
                     const double* vs, int nv, double* out) {
  // Jets start zeroed, which costs about as much as computing them: as few
  // as the grid needs (the tree's 3 x 3 nodes mostly).
  if (nu * nv <= 9) {
    SurfaceJet jets[9];
    return MassDensityGridIn(surface, density, us, nu, vs, nv, out, jets);
  }
  SurfaceJet jets[kMassDensityGridPoints];
  MassDensityGridIn(surface, density, us, nu, vs, nv, out, jets);
}

absl::Status CheckDensityValue(double delta, double u, double v) {
  if (std::isfinite(delta) && delta >= 0) return absl::OkStatus();
  return absl::InvalidArgumentError(absl::StrFormat(
      "the density is %g at (u,v) = (%.17g, %.17g); densities must be finite and >= 0", delta, u,
      v));
}

absl::Status SurfaceNotFiniteError(double u, double v) {
  return absl::InvalidArgumentError(absl::StrFormat(
      "the surface is not finite (NaN or infinity) at (u,v) = (%.17g, %.17g); fix its formula or "
      "parameter box so it is defined everywhere on the box",
      u, v));
}

double Diagonal(const Vec3& lo, const Vec3& hi) {
  return std::hypot(std::hypot(hi.x - lo.x, hi.y - lo.y), hi.z - lo.z);
}

absl::Status CheckSize(std::string_view what, double diagonal) {
  if (diagonal == 0 || (diagonal >= kSmallestSize && diagonal <= kLargestSize)) {
    return absl::OkStatus();
  }
  return absl::InvalidArgumentError(absl::StrFormat(
      "%s spans %g (its bounding box's diagonal), outside [%g, %g], where its area element "
      "would %s double precision; scale it into that range and scale the samples back",
      what, diagonal, kSmallestSize, kLargestSize,
      diagonal > kLargestSize ? "overflow" : "lose its digits in"));
}

absl::StatusOr<DensityAt> EvaluateDensity(const Surface& surface, const Density& density, double u,
                                          double v) {
  // Curvatures and the normal are computed only for densities that read them:
  // this is the tree build's innermost call.
  return DensityFromJet(surface.Jet(u, v, density.NeedsCurvature() ? 2 : 1), density, u, v);
}

absl::Status CellMassesOnGrid(const Surface& surface, const Density& density,
                              AreaEstimator estimator, double u0, double v0, double h, int n,
                              double* masses) {
  if (estimator != AreaEstimator::kFirstFundamentalForm) {
    for (int i = 0; i < n; ++i) {
      for (int j = 0; j < n; ++j) {
        ASSIGN_OR_RETURN(masses[i * n + j],
                         CellMass(surface, density, estimator, u0 + i * h, v0 + j * h, h));
      }
    }
    return absl::OkStatus();
  }
  double us[3], vs[3];
  SurfaceJet jets[9];
  for (int i = 0; i < n; ++i) us[i] = u0 + i * h + h / 2, vs[i] = v0 + i * h + h / 2;
  surface.JetGrid(us, n, vs, n, density.NeedsCurvature() ? 2 : 1, jets);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      ASSIGN_OR_RETURN(const DensityAt d, DensityFromJet(jets[i * n + j], density, us[i], vs[j]));
      masses[i * n + j] = d.delta * d.area_element * h * h;
    }
  }
  return absl::OkStatus();
}

absl::StatusOr<double> CellMass(const Surface& surface, const Density& density,
                                AreaEstimator estimator, double u0, double v0, double h) {
  switch (estimator) {
    case AreaEstimator::kFirstFundamentalForm: {
      ASSIGN_OR_RETURN(const DensityAt d,
                       EvaluateDensity(surface, density, u0 + h / 2, v0 + h / 2));
      return d.delta * d.area_element * h * h;
    }
    case AreaEstimator::kSquare: {
      ASSIGN_OR_RETURN(const Vec3 p00, FinitePoint(surface, u0, v0));
      ASSIGN_OR_RETURN(const Vec3 p10, FinitePoint(surface, u0 + h, v0));
      ASSIGN_OR_RETURN(const Vec3 p11, FinitePoint(surface, u0 + h, v0 + h));
      ASSIGN_OR_RETURN(const Vec3 p01, FinitePoint(surface, u0, v0 + h));
      ASSIGN_OR_RETURN(const DensityAt d,
                       EvaluateDensity(surface, density, u0 + h / 2, v0 + h / 2));
      return d.delta * (TriangleArea(p00, p10, p11) + TriangleArea(p00, p11, p01));
    }
    case AreaEstimator::kQuadrature: {
      // 3-point Gauss-Legendre on [0,1]: exact for polynomials of degree 5.
      static constexpr double kNode[3] = {0.5 - 0.3872983346207417, 0.5, 0.5 + 0.3872983346207417};
      static constexpr double kWeight[3] = {5.0 / 18, 8.0 / 18, 5.0 / 18};
      double sum = 0;
      for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
          ASSIGN_OR_RETURN(const DensityAt d,
                           EvaluateDensity(surface, density, u0 + kNode[i] * h, v0 + kNode[j] * h));
          sum += kWeight[i] * kWeight[j] * d.delta * d.area_element;
        }
      }
      return sum * h * h;
    }
    case AreaEstimator::kTriangle:
      break;
  }
  return absl::InternalError("CellMass called with the triangle estimator");
}

absl::StatusOr<double> TriangleMass(const Surface& surface, const Density& density, double prev_u,
                                    double prev_v, double cur_u, double cur_v, double next_u,
                                    double next_v) {
  ASSIGN_OR_RETURN(const Vec3 a, FinitePoint(surface, prev_u, prev_v));
  ASSIGN_OR_RETURN(const Vec3 b, FinitePoint(surface, cur_u, cur_v));
  ASSIGN_OR_RETURN(const Vec3 c, FinitePoint(surface, next_u, next_v));
  ASSIGN_OR_RETURN(const DensityAt d,
                   EvaluateDensity(surface, density, (prev_u + cur_u + next_u) / 3,
                                   (prev_v + cur_v + next_v) / 3));
  return d.delta * TriangleArea(a, b, c);
}

}  // namespace sfc
