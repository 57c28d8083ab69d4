// Internal to cad/: a face's plane, cylinder, cone, sphere or torus
// evaluated from its closed form, without the kernel's adaptors (no lease, no virtual calls):
// issue 20's "the face's analytic form extracted once into a plain
// evaluator". The arithmetic is the kernel's own (OpenCASCADE 7.6's ElSLib
// formulas, the same operations in the same order, glibc's sin and cos), so
// the values are the kernel's bit for bit; Extract checks that on sample
// points and declines a face where any bit differs, which then stays with
// the kernel.
#ifndef SFCSAMPLER_CAD_INTERNAL_CLOSED_FORM_H_
#define SFCSAMPLER_CAD_INTERNAL_CLOSED_FORM_H_

#include <BRepAdaptor_Surface.hxx>

#include <cmath>
#include <optional>

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

  // The cosine and sine of a parameter, as the kernel's formulas take them
  // (glibc's cos and sin): computed once for a row or column of a grid, they
  // give the same values as Evaluate computes point by point.
  struct Trig {
    double cos, sin;
  };
  static Trig TrigOf(double a) { return {std::cos(a), std::sin(a)}; }
  // TrigOf(u) and TrigOf(v) when the type's formulas take them (u: every
  // type but the plane; v: the sphere and the torus), else nothing computed.
  Trig TrigU(double u) const { return type != Type::kPlane ? TrigOf(u) : Trig{}; }
  Trig TrigV(double v) const {
    return type == Type::kSphere || type == Type::kTorus ? TrigOf(v) : Trig{};
  }
  // Evaluate's points (order 0) at native (u[i], v[i]) for i < n, into x, y
  // and z; a plane's in one loop the compiler vectorises (the same
  // operations, so the same bits).
  void Points(const double* u, const double* v, size_t n, double* x, double* y, double* z) const;
  // Evaluate with tu = TrigU(u) and tv = TrigV(v) given.
  void EvaluateWith(double u, double v, const Trig& tu, const Trig& tv, int order,
                    double d[][3]) const;

  // The closed form of `adaptor`'s surface, if it is a plane, cylinder, cone,
  // sphere or torus without a transformation (identity location) and
  // evaluates as the kernel does at every checked point, for every order;
  // nullopt otherwise.
  static std::optional<ClosedForm> Extract(const BRepAdaptor_Surface& adaptor);
};

}  // namespace sfc::cad

#endif  // SFCSAMPLER_CAD_INTERNAL_CLOSED_FORM_H_
