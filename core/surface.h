// Parametric surfaces f : [0,1]^2 -> R^3 and their differential geometry.
//
// Every surface maps the unit square; a surface with another native
// parameter box maps it linearly (docs/ALGORITHM.md, "Inputs and output"), so all
// derivatives here are taken with respect to the unit-square parameters.
//
// Thread-safety: Surface implementations are immutable after construction and
// their const methods may be called from many threads at once.
#ifndef SFCSAMPLER_CORE_SURFACE_H_
#define SFCSAMPLER_CORE_SURFACE_H_

#include <cstddef>
#include <optional>

#include "core/interval.h"
#include "core/types/vec3.h"

namespace sfc {

// Position and partial derivatives of f at one parameter point.
struct SurfaceJet {
  Vec3 p;              // f(u, v)
  Vec3 fu, fv;         // first derivatives
  Vec3 fuu, fuv, fvv;  // second derivatives; zero unless asked for (order 2)
};

// The axis-aligned box [lo.x, hi.x] x [lo.y, hi.y] x [lo.z, hi.z]; end points
// may be infinite.
struct Box3 {
  Vec3 lo, hi;
};

// The box of three coordinate intervals; an interval that may be NaN spans
// the whole axis.
Box3 BoxOf(const Interval& x, const Interval& y, const Interval& z);

class Surface {
 public:
  virtual ~Surface() = default;

  // f(u, v). REQUIRES: (u, v) in [0,1]^2. May return a non-finite vector for
  // a surface that is singular there; callers check (see IsFinite).
  virtual Vec3 Point(double u, double v) const = 0;

  // Position and derivatives up to `order` (1 or 2); p equals Point(u, v) bit
  // for bit. The default takes finite
  // differences of Point(): 4th-order central differences for the first
  // derivatives (one-sided 2nd order within 2h of an edge, h = 1e-3 resp.
  // 1e-5), 2nd-order central differences for the second ones (h = 1e-4).
  // Stencils never leave the unit square. Surfaces with closed forms override.
  virtual SurfaceJet Jet(double u, double v, int order) const;

  // Jets on the grid us[0..nu) x vs[0..nv): out[i * nv + j] = Jet(us[i], vs[j],
  // order). Surfaces whose formula separates in u and v override it to share
  // the work of a row or column (the tree build's inner loop); the default
  // calls Jet.
  virtual void JetGrid(const double* us, int nu, const double* vs, int nv, int order,
                       SurfaceJet* out) const;

  // Point(u[i], v[i]) for i < n, into x[i], y[i], z[i], bit for bit: one
  // call per batch. The default calls Point once a sample; the built-ins
  // override it with PointsOf (no per-sample dispatch).
  virtual void Points(const double* u, const double* v, size_t n, double* x, double* y,
                      double* z) const;

  // A box that provably holds Point(u, v) for every (u, v) in the rectangle
  // [u0,u1] x [v0,v1], as Point computes it in floating point (and as Jet's p,
  // which equals it), and the exact real value of the same formula too:
  // interval arithmetic widened for rounding (core/interval.h). nullopt when the surface cannot
  // bound itself, which is the default; callers then test points one by one. REQUIRES: 0 <= u0 <=
  // u1 <= 1 and 0 <= v0 <= v1 <= 1.
  virtual std::optional<Box3> Bound(double u0, double u1, double v0, double v1) const;

  // True when Jet's fu and fv are the same bits at every (u, v) and its second
  // derivatives are zero (an affine map: a CAD model's plane), so the area
  // element is one constant: under a uniform density every cell's quadratic
  // model is exact, and the tree's error test has nothing to find
  // (core/curve_tree.h). False, the default, for any other surface.
  virtual bool IsAffine() const { return false; }
};

// Points for a final surface class S through S::Point, inlined: what S's
// Points override calls.
template <class S>
void PointsOf(const S& surface, const double* u, const double* v, size_t n, double* x, double* y,
              double* z) {
  for (size_t i = 0; i < n; ++i) {
    const Vec3 p = surface.S::Point(u[i], v[i]);
    x[i] = p.x, y[i] = p.y, z[i] = p.z;
  }
}

// First fundamental form, normal and curvatures at one point.
struct SurfaceGeometry {
  Vec3 normal;                // unit normal fu x fv / |fu x fv| (zero if degenerate)
  double e = 0, f = 0, g = 0;  // first fundamental form E, F, G
  double area_element = 0;    // sqrt(EG - F^2) = |fu x fv|
  double gaussian_curvature = 0;  // K = (LN - M^2) / (EG - F^2)
  double mean_curvature = 0;      // H = (EN - 2FM + GL) / (2 (EG - F^2))
};

// Computes the geometry from a jet. Curvatures need an order-2 jet; they are
// zero where the area element vanishes (a singular point).
SurfaceGeometry GeometryOf(const SurfaceJet& jet);

}  // namespace sfc

#endif  // SFCSAMPLER_CORE_SURFACE_H_
