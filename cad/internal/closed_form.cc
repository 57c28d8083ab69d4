#include "cad/internal/closed_form.h"

#include <Standard_Failure.hxx>
#include <gp_Ax3.hxx>
#include <gp_Cone.hxx>
#include <gp_Cylinder.hxx>
#include <gp_Pln.hxx>
#include <gp_Sphere.hxx>
#include <gp_Torus.hxx>

#include <algorithm>
#include <cfloat>
#include <cmath>

namespace sfc::cad {
namespace {

void Set(double out[3], const gp_XYZ& v) { out[0] = v.X(), out[1] = v.Y(), out[2] = v.Z(); }

void Place(const gp_Ax3& position, ClosedForm* form) {
  Set(form->o, position.Location().XYZ());
  Set(form->x, position.XDirection().XYZ());
  Set(form->y, position.YDirection().XYZ());
  Set(form->z, position.Direction().XYZ());
}

// The kernel's D0, D1 or D2 (`order`) at (u, v), laid out as Evaluate's.
void KernelAt(const BRepAdaptor_Surface& adaptor, double u, double v, int order,
              double d[][3]) {
  gp_Pnt p;
  gp_Vec du, dv, duu, dvv, duv;
  if (order == 0) adaptor.D0(u, v, p);
  if (order == 1) adaptor.D1(u, v, p, du, dv);
  if (order == 2) adaptor.D2(u, v, p, du, dv, duu, dvv, duv);
  Set(d[0], p.XYZ());
  Set(d[1], du.XYZ());
  Set(d[2], dv.XYZ());
  Set(d[3], duu.XYZ());
  Set(d[4], dvv.XYZ());
  Set(d[5], duv.XYZ());
}

}  // namespace

void ClosedForm::TrigsOf(const double* a, size_t n, Trig* out) {
  constexpr size_t kChunk = 64;
  double s[kChunk], c[kChunk];
  for (size_t b = 0; b < n; b += kChunk) {
    const size_t m = std::min(kChunk, n - b);
    math::SinCosOf(a + b, m, s, c);
    for (size_t i = 0; i < m; ++i) out[b + i] = {c[i], s[i]};
  }
}

// Each formula is the one ElSLib (OpenCASCADE 7.6) evaluates for the type
// and order: PlaneD0/D1, CylinderD0/D1/D2, ConeD0/D1/D2, SphereD0/D1/D2,
// TorusD0/D1/D2 (with its rounding of tiny terms to zero).
void ClosedForm::Evaluate(double u, double v, int order, double d[][3]) const {
  EvaluateWith(u, v, TrigU(u), TrigV(v), order, d);
}

void ClosedForm::EvaluateWith(double u, double v, const Trig& tu, const Trig& tv, int order,
                              double d[][3]) const {
  switch (type) {
    case Type::kPlane:
      for (int k = 0; k < 3; ++k) d[0][k] = u * x[k] + v * y[k] + o[k];
      if (order >= 1) {
        for (int k = 0; k < 3; ++k) d[1][k] = x[k], d[2][k] = y[k];
      }
      if (order >= 2) {
        for (int k = 0; k < 3; ++k) d[3][k] = d[4][k] = d[5][k] = 0.0;
      }
      return;
    case Type::kCylinder: {
      const double a1 = radius * tu.cos, a2 = radius * tu.sin;
      if (order < 2) {
        for (int k = 0; k < 3; ++k) d[0][k] = a1 * x[k] + a2 * y[k] + v * z[k] + o[k];
      } else {
        for (int k = 0; k < 3; ++k) {
          const double som = a1 * x[k] + a2 * y[k];
          d[0][k] = som + v * z[k] + o[k];
          d[3][k] = -som;
          d[4][k] = d[5][k] = 0.0;
        }
      }
      if (order >= 1) {
        for (int k = 0; k < 3; ++k) d[1][k] = -a2 * x[k] + a1 * y[k], d[2][k] = z[k];
      }
      return;
    }
    case Type::kCone: {
      if (order == 0) {
        const double r = radius + v * sin_angle, a3 = v * cos_angle;
        const double a1 = r * tu.cos, a2 = r * tu.sin;
        for (int k = 0; k < 3; ++k) d[0][k] = a1 * x[k] + a2 * y[k] + a3 * z[k] + o[k];
        return;
      }
      const double cu = tu.cos, su = tu.sin;
      const double ca = cos_angle, sa = sin_angle;
      const double r = radius + v * sa, a3 = v * ca;
      const double a1 = r * cu, a2 = r * su, r1 = sa * cu, r2 = sa * su;
      for (int k = 0; k < 3; ++k) {
        if (order == 1) {
          d[0][k] = a1 * x[k] + a2 * y[k] + a3 * z[k] + o[k];
        } else {
          const double som = a1 * x[k] + a2 * y[k];
          d[0][k] = som + a3 * z[k] + o[k];
          d[3][k] = -som;
          d[4][k] = 0.0;
          d[5][k] = -r2 * x[k] + r1 * y[k];
        }
        d[1][k] = -a2 * x[k] + a1 * y[k];
        d[2][k] = r1 * x[k] + r2 * y[k] + ca * z[k];
      }
      return;
    }
    case Type::kTorus: {
      const double eps = 10. * (minor + radius) * DBL_EPSILON;
      auto tiny = [eps](double a) { return std::abs(a) <= eps ? 0. : a; };
      if (order == 0) {
        const double r = radius + minor * tv.cos, a3 = tiny(minor * tv.sin);
        const double a1 = tiny(r * tu.cos), a2 = tiny(r * tu.sin);
        for (int k = 0; k < 3; ++k) d[0][k] = a1 * x[k] + a2 * y[k] + a3 * z[k] + o[k];
        return;
      }
      const double cu = tu.cos, su = tu.sin;
      const double r1 = minor * tv.cos, r2 = minor * tv.sin;
      const double r = radius + r1;
      const double a1 = tiny(r * cu), a2 = tiny(r * su), a3 = tiny(r2 * cu), a4 = tiny(r2 * su);
      for (int k = 0; k < 3; ++k) {
        if (order == 1) {
          d[0][k] = a1 * x[k] + a2 * y[k] + r2 * z[k] + o[k];
        } else {
          const double a5 = tiny(r1 * cu), a6 = tiny(r1 * su);
          const double som = a1 * x[k] + a2 * y[k], r2z = r2 * z[k];
          d[0][k] = som + r2z + o[k];
          d[3][k] = -som;
          d[4][k] = -a5 * x[k] - a6 * y[k] - r2z;
          d[5][k] = a4 * x[k] - a3 * y[k];
        }
        d[1][k] = -a2 * x[k] + a1 * y[k];
        d[2][k] = -a3 * x[k] - a4 * y[k] + r1 * z[k];
      }
      return;
    }
    case Type::kSphere: {
      if (order == 0) {
        const double r = radius * tv.cos, a3 = radius * tv.sin;
        const double a1 = r * tu.cos, a2 = r * tu.sin;
        for (int k = 0; k < 3; ++k) d[0][k] = a1 * x[k] + a2 * y[k] + a3 * z[k] + o[k];
        return;
      }
      const double cu = tu.cos, su = tu.sin;
      const double r1 = radius * tv.cos, r2 = radius * tv.sin;
      const double a1 = r1 * cu, a2 = r1 * su, a3 = r2 * cu, a4 = r2 * su;
      for (int k = 0; k < 3; ++k) {
        if (order == 1) {
          d[0][k] = a1 * x[k] + a2 * y[k] + r2 * z[k] + o[k];
        } else {
          const double som = a1 * x[k] + a2 * y[k], r2z = r2 * z[k];
          d[0][k] = som + r2z + o[k];
          d[3][k] = -som;
          d[4][k] = -som - r2z;
          d[5][k] = a4 * x[k] - a3 * y[k];
        }
        d[1][k] = -a2 * x[k] + a1 * y[k];
        d[2][k] = -a3 * x[k] - a4 * y[k] + r1 * z[k];
      }
      return;
    }
  }
}

void ClosedForm::Points(const double* u, const double* v, size_t n, double* px, double* py,
                        double* pz) const {
  if (type == Type::kPlane) {  // EvaluateWith's plane, order 0
    for (size_t i = 0; i < n; ++i) {
      px[i] = u[i] * x[0] + v[i] * y[0] + o[0];
      py[i] = u[i] * x[1] + v[i] * y[1] + o[1];
      pz[i] = u[i] * x[2] + v[i] * y[2] + o[2];
    }
    return;
  }
  // The sines and cosines a chunk at a time (the same bits as TrigU and
  // TrigV point by point), then EvaluateWith's formulas.
  constexpr size_t kChunk = 128;
  Trig tu[kChunk], tv[kChunk];
  for (size_t b = 0; b < n; b += kChunk) {
    const size_t m = std::min(kChunk, n - b);
    TrigsOf(u + b, m, tu);
    if (TakesTrigV()) TrigsOf(v + b, m, tv);
    for (size_t i = 0; i < m; ++i) {
      double d[6][3];
      EvaluateWith(u[b + i], v[b + i], tu[i], TakesTrigV() ? tv[i] : Trig{}, 0, d);
      px[b + i] = d[0][0], py[b + i] = d[0][1], pz[b + i] = d[0][2];
    }
  }
}

std::optional<ClosedForm> ClosedForm::FormOf(const Adaptor3d_Surface& surface) {
  ClosedForm form;
  try {
    switch (surface.GetType()) {
      case GeomAbs_Plane:
        form.type = Type::kPlane;
        Place(surface.Plane().Position(), &form);
        break;
      case GeomAbs_Cylinder:
        form.type = Type::kCylinder;
        Place(surface.Cylinder().Position(), &form);
        form.radius = surface.Cylinder().Radius();
        break;
      case GeomAbs_Cone:
        form.type = Type::kCone;
        Place(surface.Cone().Position(), &form);
        form.radius = surface.Cone().RefRadius();
        form.sin_angle = math::SinCosOf(surface.Cone().SemiAngle()).sin;
        form.cos_angle = math::SinCosOf(surface.Cone().SemiAngle()).cos;
        break;
      case GeomAbs_Sphere:
        form.type = Type::kSphere;
        Place(surface.Sphere().Position(), &form);
        form.radius = surface.Sphere().Radius();
        break;
      case GeomAbs_Torus:
        form.type = Type::kTorus;
        Place(surface.Torus().Position(), &form);
        form.radius = surface.Torus().MajorRadius();
        form.minor = surface.Torus().MinorRadius();
        break;
      default:
        return std::nullopt;
    }
  } catch (const Standard_Failure&) {
    return std::nullopt;
  }
  return form;
}

Box3 ClosedForm::Bound(const Interval& u, const Interval& v) const {
  // EvaluateWith's order-0 formulas, operation for operation, on intervals.
  const Interval nan = Interval::NaN();
  const Interval cu = TakesTrigU() ? Cos(u) : nan, su = TakesTrigU() ? Sin(u) : nan;
  const Interval cv = TakesTrigV() ? Cos(v) : nan, sv = TakesTrigV() ? Sin(v) : nan;
  Interval a1, a2, a3;
  switch (type) {
    case Type::kPlane:
      a1 = u, a2 = v, a3 = Interval::Point(0);
      break;
    case Type::kCylinder:
      a1 = Interval::Point(radius) * cu, a2 = Interval::Point(radius) * su, a3 = v;
      break;
    case Type::kCone: {
      const Interval r = Interval::Point(radius) + v * Interval::Point(sin_angle);
      a1 = r * cu, a2 = r * su, a3 = v * Interval::Point(cos_angle);
      break;
    }
    case Type::kSphere: {
      const Interval r = Interval::Point(radius) * cv;
      a1 = r * cu, a2 = r * su, a3 = Interval::Point(radius) * sv;
      break;
    }
    case Type::kTorus: {
      // tiny() maps values within eps of 0 to 0: the interval of its image
      // holds both.
      const double eps = 10. * (minor + radius) * DBL_EPSILON;
      auto tiny = [eps](const Interval& a) {
        return a.maybe_nan || (a.lo <= eps && a.hi >= -eps) ? Hull(a, Interval::Point(0)) : a;
      };
      const Interval r = Interval::Point(radius) + Interval::Point(minor) * cv;
      a1 = tiny(r * cu), a2 = tiny(r * su), a3 = tiny(Interval::Point(minor) * sv);
      break;
    }
  }
  Interval p[3];
  for (int k = 0; k < 3; ++k) {
    if (type == Type::kPlane) {  // u * x + v * y + o
      p[k] = a1 * Interval::Point(x[k]) + a2 * Interval::Point(y[k]) + Interval::Point(o[k]);
    } else {  // a1 * x + a2 * y + a3 * z + o
      p[k] = a1 * Interval::Point(x[k]) + a2 * Interval::Point(y[k]) + a3 * Interval::Point(z[k]) +
             Interval::Point(o[k]);
    }
  }
  return BoxOf(p[0], p[1], p[2]);
}

std::optional<ClosedForm> ClosedForm::Extract(const BRepAdaptor_Surface& adaptor) {
  if (adaptor.Trsf().Form() != gp_Identity) return std::nullopt;
  std::optional<ClosedForm> found = FormOf(adaptor.Surface());
  if (!found) return std::nullopt;
  ClosedForm form = *found;
  try {
    // The kernel's values on a grid of its parameter box, and well outside
    // it, for every order, within kTolerance of the form's size (or of the
    // value's, where that is larger: a derivative along a length is a unit
    // vector's size).
    const double u0 = adaptor.FirstUParameter(), u1 = adaptor.LastUParameter();
    const double v0 = adaptor.FirstVParameter(), v1 = adaptor.LastVParameter();
    auto at = [](double a0, double a1, int i, double step, double shift) {
      return a0 + (a1 - a0) * (i * step + shift) - 0.05 * (a1 - a0);
    };
    double size = std::max({std::abs(form.o[0]), std::abs(form.o[1]), std::abs(form.o[2]),
                            std::abs(form.radius) + std::abs(form.minor)});
    for (int i = 0; i <= 8; ++i) {
      size = std::max({size, std::abs(at(u0, u1, i, 0.1371, 0.0113)),
                       std::abs(at(v0, v1, i, 0.1297, 0.0171))});
    }
    if (!std::isfinite(size)) return std::nullopt;
    for (int i = 0; i <= 8; ++i) {
      for (int j = 0; j <= 8; ++j) {
        const double u = at(u0, u1, i, 0.1371, 0.0113), v = at(v0, v1, j, 0.1297, 0.0171);
        for (int order = 0; order <= 2; ++order) {
          double ours[6][3], theirs[6][3];
          form.Evaluate(u, v, order, ours);
          KernelAt(adaptor, u, v, order, theirs);
          const int rows = order == 0 ? 1 : order == 1 ? 3 : 6;
          for (int r = 0; r < rows; ++r) {
            const double scale = std::max(
                {size, std::abs(theirs[r][0]), std::abs(theirs[r][1]), std::abs(theirs[r][2])});
            for (int k = 0; k < 3; ++k) {
              if (!(std::abs(ours[r][k] - theirs[r][k]) <= kTolerance * scale)) {
                return std::nullopt;
              }
            }
          }
        }
      }
    }
  } catch (const Standard_Failure&) {
    return std::nullopt;
  }
  return form;
}

}  // namespace sfc::cad
