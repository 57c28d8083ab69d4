#include "core/surface.h"

#include <algorithm>
#include <limits>

namespace sfc {
namespace {

// d/dx of a scalar-to-Vec3 function g at x in [0,1]: central 4th order where
// the stencil fits, otherwise a one-sided 2nd-order stencil pointing inward.
template <typename G>
Vec3 FirstDerivative(const G& g, double x) {
  constexpr double kCentral = 1e-3;
  constexpr double kOneSided = 1e-5;
  if (x - 2 * kCentral >= 0 && x + 2 * kCentral <= 1) {
    const double h = kCentral;
    return (g(x - 2 * h) - 8.0 * g(x - h) + 8.0 * g(x + h) - g(x + 2 * h)) * (1.0 / (12 * h));
  }
  const double h = x + 2 * kOneSided <= 1 ? kOneSided : -kOneSided;
  return (-3.0 * g(x) + 4.0 * g(x + h) - g(x + 2 * h)) * (1.0 / (2 * h));
}

}  // namespace

SurfaceJet Surface::Jet(double u, double v, int order) const {
  SurfaceJet jet;
  jet.p = Point(u, v);
  jet.fu = FirstDerivative([&](double s) { return Point(s, v); }, u);
  jet.fv = FirstDerivative([&](double t) { return Point(u, t); }, v);
  if (order >= 2) {
    constexpr double h = 1e-4;
    // Second differences about a centre kept h inside the square.
    const double cu = std::clamp(u, h, 1 - h);
    const double cv = std::clamp(v, h, 1 - h);
    const Vec3 c = Point(cu, cv);
    jet.fuu = (Point(cu - h, cv) - 2.0 * c + Point(cu + h, cv)) * (1.0 / (h * h));
    jet.fvv = (Point(cu, cv - h) - 2.0 * c + Point(cu, cv + h)) * (1.0 / (h * h));
    jet.fuv = (Point(cu + h, cv + h) - Point(cu + h, cv - h) - Point(cu - h, cv + h) +
               Point(cu - h, cv - h)) *
              (1.0 / (4 * h * h));
  }
  return jet;
}

void Surface::JetGrid(const double* us, int nu, const double* vs, int nv, int order,
                      SurfaceJet* out) const {
  for (int i = 0; i < nu; ++i) {
    for (int j = 0; j < nv; ++j) out[i * nv + j] = Jet(us[i], vs[j], order);
  }
}

void Surface::Points(const double* u, const double* v, size_t n, double* x, double* y,
                     double* z) const {
  for (size_t i = 0; i < n; ++i) {
    const Vec3 p = Point(u[i], v[i]);
    x[i] = p.x, y[i] = p.y, z[i] = p.z;
  }
}

Box3 BoxOf(const Interval& x, const Interval& y, const Interval& z) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  auto lo = [&](const Interval& i) { return i.maybe_nan ? -kInf : i.lo; };
  auto hi = [&](const Interval& i) { return i.maybe_nan ? kInf : i.hi; };
  return {{lo(x), lo(y), lo(z)}, {hi(x), hi(y), hi(z)}};
}

std::optional<Box3> Surface::Bound(double, double, double, double) const { return std::nullopt; }

SurfaceGeometry GeometryOf(const SurfaceJet& jet) {
  SurfaceGeometry geo;
  geo.e = Dot(jet.fu, jet.fu);
  geo.f = Dot(jet.fu, jet.fv);
  geo.g = Dot(jet.fv, jet.fv);
  const Vec3 n = Cross(jet.fu, jet.fv);
  geo.area_element = Norm(n);
  if (!(geo.area_element > 0)) return geo;
  geo.normal = n * (1.0 / geo.area_element);
  const double l = Dot(jet.fuu, geo.normal);
  const double m = Dot(jet.fuv, geo.normal);
  const double nn = Dot(jet.fvv, geo.normal);
  const double det = geo.area_element * geo.area_element;
  geo.gaussian_curvature = (l * nn - m * m) / det;
  geo.mean_curvature = (geo.e * nn - 2 * geo.f * m + geo.g * l) / (2 * det);
  return geo;
}

}  // namespace sfc
