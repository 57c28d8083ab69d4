// Internal to cad/: a face's plane, cylinder, cone, sphere or torus
// evaluated from its closed form, without the kernel's adaptors (no lease, no virtual calls):
// issue 20's "the face's analytic form extracted once into a plain
// evaluator". The formulas are the kernel's own (OpenCASCADE 7.6's ElSLib,
// the same operations in the same order), but the sines and cosines are
// SLEEF's (math::SinCosOf, core/vector_math.h), not glibc's, so a face's
// values are the same bits on every machine (glibc picks FMA variants of sin
// and cos where the CPU has FMA). They are within a few ulp of the kernel's:
// Extract checks that on sample points (kTolerance) and declines a face that
// differs more, which then stays with the kernel.
#ifndef SFCSAMPLER_CAD_INTERNAL_CLOSED_FORM_H_
#define SFCSAMPLER_CAD_INTERNAL_CLOSED_FORM_H_

#include <Adaptor3d_Surface.hxx>
#include <BRepAdaptor_Surface.hxx>
#include <cmath>
#include <optional>

#include "core/interval.h"
#include "core/surface.h"
#include "core/vector_math.h"

namespace sfc::cad {

struct ClosedForm {
  enum class Type { kPlane, kCylinder, kCone, kSphere, kTorus };
  Type type = Type::kPlane;
  // The surface's placement (location; x, y and main directions), radius (a
  // torus's major one), a torus's minor radius and the sine and cosine of a
  // cone's semi-angle.
  double o[3], x[3], y[3], z[3];
  double radius = 0, minor = 0, sin_angle = 0, cos_angle = 0;

  // In the kernel's native parameters (U, V); d[0] is the point, d[1], d[2]
  // the first derivatives (U, V), d[3], d[4], d[5] the second (UU, VV, UV),
  // as BRepAdaptor_Surface::D0, D1 and D2 give them for `order` 0, 1, 2.
  void Evaluate(double u, double v, int order, double d[][3]) const;

  // The cosine and sine of a parameter (math::SinCosOf): computed once for
  // a row or column of a grid, or a batch at a time (TrigsOf), they give the
  // same values as Evaluate computes point by point.
  struct Trig {
    double cos, sin;
  };
  static Trig TrigOf(double a) {
    const math::SinCos t = math::SinCosOf(a);
    return {t.cos, t.sin};
  }
  // TrigOf(a[i]) for i < n into out[i], bit for bit, on the widest vector
  // path (math::SinCosOf's batch).
  static void TrigsOf(const double* a, size_t n, Trig* out);
  // Whether the type's formulas take the sine and cosine of u (every type but
  // the plane) and of v (the sphere and the torus).
  bool TakesTrigU() const { return type != Type::kPlane; }
  bool TakesTrigV() const { return type == Type::kSphere || type == Type::kTorus; }
  // TrigOf(u) and TrigOf(v) when the type's formulas take them (u: every
  // type but the plane; v: the sphere and the torus), else nothing computed.
  Trig TrigU(double u) const { return TakesTrigU() ? TrigOf(u) : Trig{}; }
  Trig TrigV(double v) const { return TakesTrigV() ? TrigOf(v) : Trig{}; }
  // Evaluate's points (order 0) at native (u[i], v[i]) for i < n, into x, y
  // and z, bit for bit: a plane's in one loop the compiler vectorises (the
  // same operations), the other types' sines and cosines in batches.
  void Points(const double* u, const double* v, size_t n, double* x, double* y, double* z) const;
  // Evaluate with tu = TrigU(u) and tv = TrigV(v) given.
  void EvaluateWith(double u, double v, const Trig& tu, const Trig& tv, int order,
                    double d[][3]) const;

  // A box holding Evaluate's point (order 0) at every native (u, v) in the
  // intervals u x v, as the double code computes it and as the exact real
  // formula gives it: EvaluateWith's order-0 formula on intervals
  // (core/interval.h, whose sines and cosines are SLEEF's, so the same bits
  // on every CPU). What FaceSurface::Bound answers for a closed-form face.
  Box3 Bound(const Interval& u, const Interval& v) const;

  // The form of a plane, cylinder, cone, sphere or torus as `surface`
  // describes it (a BRepAdaptor_Surface's with the face's location applied),
  // unchecked against the kernel's evaluation; nullopt for any other type.
  static std::optional<ClosedForm> FormOf(const Adaptor3d_Surface& surface);

  // How far Extract lets a closed form's value be from the kernel's, as a
  // fraction of the form's size (the largest of its origin's coordinates, its
  // radii and the parameters checked): a few ulp, as the two sines differ by
  // at most 2 ulp and the formulas are the same operations. A wrong formula
  // is off by a fraction of the size itself.
  static constexpr double kTolerance = 16 * 2.220446049250313e-16;
  // The closed form of `adaptor`'s surface, if it is a plane, cylinder, cone,
  // sphere or torus without a transformation (identity location) and
  // evaluates as the kernel does, within kTolerance, at every checked point
  // for every order (points and first and second derivatives); nullopt
  // otherwise.
  static std::optional<ClosedForm> Extract(const BRepAdaptor_Surface& adaptor);
};

}  // namespace sfc::cad

#endif  // SFCSAMPLER_CAD_INTERNAL_CLOSED_FORM_H_
