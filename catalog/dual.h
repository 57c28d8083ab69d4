// Forward-mode dual numbers in the two surface parameters (u, v): a value
// with its gradient and, for order 2, its Hessian, carried through every
// operation of a user expression in one pass (automatic differentiation;
// docs/ALGORITHM.md needs f_u, f_v for the area element and f_uu, f_uv, f_vv for
// curvature densities).
//
// The value part of every operation is computed exactly as the plain-double
// evaluation computes it (same operations, same order), so a Jet's position
// is bit-identical to Point() at the same parameters. Derivatives follow the
// chain rule with closed-form first and second derivatives of each function,
// exact up to rounding. Where a function is not differentiable (abs at 0,
// sign, rint, min/max at a tie) the derivative of the branch taken is used.
//
// Value type; thread-compatible; all functions are pure.
#ifndef SFCSAMPLER_CATALOG_DUAL_H_
#define SFCSAMPLER_CATALOG_DUAL_H_

#include <cmath>

#include "core/vector_math.h"

namespace sfc {

// muparser's semantics of the functions that are not plain C library calls.
inline double AbsOf(double x) { return x >= 0 ? x : -x; }
inline double SignOf(double x) { return x < 0 ? -1 : x > 0 ? 1 : 0; }
inline double RintOf(double x) { return std::floor(x + 0.5); }
inline double MinOf(double a, double b) { return b < a ? b : a; }  // std::min
inline double MaxOf(double a, double b) { return a < b ? b : a; }  // std::max
// sin and cos of x in one library call. Every path (double, dual, constant
// folding) takes sin and cos from here, so they agree bit for bit.
inline void SinCosOf(double x, double* s, double* c) {
  const math::SinCos r = math::SinCosOf(x);
  *s = r.sin, *c = r.cos;
}

// kOrder 1: value and gradient. kOrder 2: also the Hessian.
template <int kOrder>
struct Dual {
  static_assert(kOrder == 1 || kOrder == 2, "orders 1 and 2");
  double v;     // value
  double d[2];  // d/du, d/dv
  double h[kOrder == 2 ? 3 : 1];  // d2/du2, d2/dudv, d2/dv2 (order 2 only)

  static Dual Constant(double c) {
    Dual r;
    r.v = c, r.d[0] = r.d[1] = 0;
    if constexpr (kOrder == 2) r.h[0] = r.h[1] = r.h[2] = 0;
    return r;
  }
  // value + du * (u - u_0) + dv * (v - v_0): an affine function of (u, v).
  static Dual Affine(double value, double du, double dv) {
    Dual r = Constant(value);
    r.d[0] = du, r.d[1] = dv;
    return r;
  }
  bool IsConstant() const {
    if constexpr (kOrder == 2) {
      if (h[0] != 0 || h[1] != 0 || h[2] != 0) return false;
    }
    return d[0] == 0 && d[1] == 0;
  }
};

using Dual1 = Dual<1>;
using Dual2 = Dual<2>;

// g(a) for a scalar g with g(a.v) = f0, g' = f1, g'' = f2.
template <int N>
Dual<N> Chain(const Dual<N>& a, double f0, double f1, double f2) {
  Dual<N> r;
  r.v = f0;
  r.d[0] = f1 * a.d[0], r.d[1] = f1 * a.d[1];
  if constexpr (N == 2) {
    r.h[0] = f1 * a.h[0] + f2 * a.d[0] * a.d[0];
    r.h[1] = f1 * a.h[1] + f2 * a.d[0] * a.d[1];
    r.h[2] = f1 * a.h[2] + f2 * a.d[1] * a.d[1];
  }
  return r;
}

// g(a, b) with value f0 and partial derivatives fa, fb, faa, fab, fbb.
template <int N>
Dual<N> Chain2(const Dual<N>& a, const Dual<N>& b, double f0, double fa, double fb, double faa,
               double fab, double fbb) {
  Dual<N> r;
  r.v = f0;
  for (int i = 0; i < 2; ++i) r.d[i] = fa * a.d[i] + fb * b.d[i];
  if constexpr (N == 2) {
    const int ii[3] = {0, 0, 1}, jj[3] = {0, 1, 1};
    for (int k = 0; k < 3; ++k) {
      const int i = ii[k], j = jj[k];
      r.h[k] = fa * a.h[k] + fb * b.h[k] + faa * a.d[i] * a.d[j] +
               fab * (a.d[i] * b.d[j] + a.d[j] * b.d[i]) + fbb * b.d[i] * b.d[j];
    }
  }
  return r;
}

template <int N>
Dual<N> operator+(const Dual<N>& a, const Dual<N>& b) {
  Dual<N> r;
  r.v = a.v + b.v;
  r.d[0] = a.d[0] + b.d[0], r.d[1] = a.d[1] + b.d[1];
  if constexpr (N == 2)
    r.h[0] = a.h[0] + b.h[0], r.h[1] = a.h[1] + b.h[1], r.h[2] = a.h[2] + b.h[2];
  return r;
}

template <int N>
Dual<N> operator-(const Dual<N>& a) {
  Dual<N> r;
  r.v = -a.v;
  r.d[0] = -a.d[0], r.d[1] = -a.d[1];
  if constexpr (N == 2) r.h[0] = -a.h[0], r.h[1] = -a.h[1], r.h[2] = -a.h[2];
  return r;
}

template <int N>
Dual<N> operator-(const Dual<N>& a, const Dual<N>& b) {
  Dual<N> r;
  r.v = a.v - b.v;
  r.d[0] = a.d[0] - b.d[0], r.d[1] = a.d[1] - b.d[1];
  if constexpr (N == 2)
    r.h[0] = a.h[0] - b.h[0], r.h[1] = a.h[1] - b.h[1], r.h[2] = a.h[2] - b.h[2];
  return r;
}

template <int N>
Dual<N> operator*(const Dual<N>& a, const Dual<N>& b) {
  Dual<N> r;
  r.v = a.v * b.v;
  r.d[0] = a.d[0] * b.v + a.v * b.d[0];
  r.d[1] = a.d[1] * b.v + a.v * b.d[1];
  if constexpr (N == 2) {
    r.h[0] = a.h[0] * b.v + 2 * a.d[0] * b.d[0] + a.v * b.h[0];
    r.h[1] = a.h[1] * b.v + a.d[0] * b.d[1] + a.d[1] * b.d[0] + a.v * b.h[1];
    r.h[2] = a.h[2] * b.v + 2 * a.d[1] * b.d[1] + a.v * b.h[2];
  }
  return r;
}

// a * c + k for constants c, k (muparser's fused "variable times constant
// plus constant"), evaluated as the double path does.
template <int N>
Dual<N> MulAdd(const Dual<N>& a, double c, double k) {
  Dual<N> r;
  r.v = a.v * c + k;
  r.d[0] = a.d[0] * c, r.d[1] = a.d[1] * c;
  if constexpr (N == 2) r.h[0] = a.h[0] * c, r.h[1] = a.h[1] * c, r.h[2] = a.h[2] * c;
  return r;
}

template <int N>
Dual<N> operator/(const Dual<N>& a, const Dual<N>& b) {
  const double q = 1 / b.v;
  if (b.IsConstant()) {  // the common case: a / constant
    Dual<N> r = Chain(a, a.v / b.v, q, 0);
    return r;
  }
  return Chain2(a, b, a.v / b.v, q, -a.v * q * q, 0, -q * q, 2 * a.v * q * q * q);
}

template <int N>
Dual<N> Pow(const Dual<N>& a, const Dual<N>& b) {
  const double value = math::Pow(a.v, b.v);
  if (b.IsConstant()) {
    const double n = b.v;
    if (n == 0) return Dual<N>::Constant(value);
    const double f1 = n * math::Pow(a.v, n - 1);
    double f2 = 0;
    if constexpr (N == 2) f2 = n == 1 ? 0 : n * (n - 1) * math::Pow(a.v, n - 2);
    return Chain(a, value, f1, f2);
  }
  const double ln = math::Log(a.v);
  if (a.IsConstant()) return Chain(b, value, value * ln, value * ln * ln);
  const double pb1 = math::Pow(a.v, b.v - 1);
  return Chain2(a, b, value, b.v * pb1, value * ln, b.v * (b.v - 1) * math::Pow(a.v, b.v - 2),
                pb1 * (1 + b.v * ln), value * ln * ln);
}

// sin(a) and cos(a) given s = sin(a.v) and c = cos(a.v).
template <int N>
Dual<N> SinFrom(const Dual<N>& a, double s, double c) {
  return Chain(a, s, c, -s);
}
template <int N>
Dual<N> CosFrom(const Dual<N>& a, double s, double c) {
  return Chain(a, c, -s, -c);
}
template <int N>
Dual<N> Sin(const Dual<N>& a) {
  double s, c;
  SinCosOf(a.v, &s, &c);
  return SinFrom(a, s, c);
}
template <int N>
Dual<N> Cos(const Dual<N>& a) {
  double s, c;
  SinCosOf(a.v, &s, &c);
  return CosFrom(a, s, c);
}
template <int N>
Dual<N> Tan(const Dual<N>& a) {
  const double t = math::Tan(a.v), sec2 = 1 + t * t;
  return Chain(a, t, sec2, 2 * t * sec2);
}
template <int N>
Dual<N> Asin(const Dual<N>& a) {
  const double f1 = 1 / std::sqrt(1 - a.v * a.v);
  return Chain(a, math::Asin(a.v), f1, a.v * f1 * f1 * f1);
}
template <int N>
Dual<N> Acos(const Dual<N>& a) {
  const double f1 = 1 / std::sqrt(1 - a.v * a.v);
  return Chain(a, math::Acos(a.v), -f1, -a.v * f1 * f1 * f1);
}
template <int N>
Dual<N> Atan(const Dual<N>& a) {
  const double f1 = 1 / (1 + a.v * a.v);
  return Chain(a, math::Atan(a.v), f1, -2 * a.v * f1 * f1);
}
// atan2(y, x).
template <int N>
Dual<N> Atan2(const Dual<N>& y, const Dual<N>& x) {
  const double r2 = x.v * x.v + y.v * y.v, r4 = r2 * r2;
  return Chain2(y, x, math::Atan2(y.v, x.v), x.v / r2, -y.v / r2, -2 * x.v * y.v / r4,
                (y.v * y.v - x.v * x.v) / r4, 2 * x.v * y.v / r4);
}
template <int N>
Dual<N> Sinh(const Dual<N>& a) {
  const double s = math::Sinh(a.v);
  return Chain(a, s, math::Cosh(a.v), s);
}
template <int N>
Dual<N> Cosh(const Dual<N>& a) {
  const double c = math::Cosh(a.v);
  return Chain(a, c, math::Sinh(a.v), c);
}
template <int N>
Dual<N> Tanh(const Dual<N>& a) {
  const double t = math::Tanh(a.v), f1 = 1 - t * t;
  return Chain(a, t, f1, -2 * t * f1);
}
template <int N>
Dual<N> Asinh(const Dual<N>& a) {
  const double f1 = 1 / std::sqrt(a.v * a.v + 1);
  return Chain(a, math::Asinh(a.v), f1, -a.v * f1 * f1 * f1);
}
template <int N>
Dual<N> Acosh(const Dual<N>& a) {
  const double f1 = 1 / std::sqrt(a.v * a.v - 1);
  return Chain(a, math::Acosh(a.v), f1, -a.v * f1 * f1 * f1);
}
template <int N>
Dual<N> Atanh(const Dual<N>& a) {
  const double f1 = 1 / (1 - a.v * a.v);
  return Chain(a, math::Atanh(a.v), f1, 2 * a.v * f1 * f1);
}
template <int N>
Dual<N> Exp(const Dual<N>& a) {
  const double e = math::Exp(a.v);
  return Chain(a, e, e, e);
}
template <int N>
Dual<N> Log(const Dual<N>& a) {
  const double q = 1 / a.v;
  return Chain(a, math::Log(a.v), q, -q * q);
}
template <int N>
Dual<N> Log2(const Dual<N>& a) {
  const double q = 1 / (a.v * 0.69314718055994530942);  // ln 2
  return Chain(a, math::Log2(a.v), q, -q / a.v);
}
template <int N>
Dual<N> Log10(const Dual<N>& a) {
  const double q = 1 / (a.v * 2.30258509299404568402);  // ln 10
  return Chain(a, math::Log10(a.v), q, -q / a.v);
}
template <int N>
Dual<N> Sqrt(const Dual<N>& a) {
  const double s = std::sqrt(a.v), f1 = 0.5 / s;
  return Chain(a, s, f1, -0.5 * f1 / a.v);
}
template <int N>
Dual<N> Abs(const Dual<N>& a) {
  return Chain(a, AbsOf(a.v), a.v >= 0 ? 1 : -1, 0);
}
template <int N>
Dual<N> Sign(const Dual<N>& a) {
  return Dual<N>::Constant(SignOf(a.v));
}
template <int N>
Dual<N> Rint(const Dual<N>& a) {
  return Dual<N>::Constant(RintOf(a.v));
}
template <int N>
Dual<N> Min(const Dual<N>& a, const Dual<N>& b) {
  return b.v < a.v ? b : a;
}
template <int N>
Dual<N> Max(const Dual<N>& a, const Dual<N>& b) {
  return a.v < b.v ? b : a;
}

}  // namespace sfc

#endif  // SFCSAMPLER_CATALOG_DUAL_H_
