#include "core/interval.h"

#include <algorithm>
#include <cmath>

#include "core/vector_math.h"

namespace sfc {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kPi = 3.14159265358979323846;
// Absolute slack under the relative library margin, for results in the
// subnormal range where a few ulp are an absolute error.
constexpr double kTiny = 1e-300;
// Beyond this magnitude the periodic functions return their full range: the
// argument reduction in HasCritical would lose its tolerance.
constexpr double kPeriodicLimit = 1e6;

// One ulp outward, for correctly rounded operations.
double Down(double x) { return std::nextafter(x, -kInf); }
double Up(double x) { return std::nextafter(x, kInf); }
// The library margin outward, for elementary functions and composite steps.
double LibDown(double x) {
  return std::isfinite(x) ? x - (std::fabs(x) * kLibmMargin + kTiny) : x;
}
double LibUp(double x) { return std::isfinite(x) ? x + (std::fabs(x) * kLibmMargin + kTiny) : x; }

// [lo, hi], or the NaN interval when an end point is NaN.
Interval Make(double lo, double hi) {
  if (std::isnan(lo) || std::isnan(hi)) return Interval::NaN();
  return Interval::Of(lo, hi);
}
Interval LibMake(double a, double b) {
  return Make(LibDown(std::min(a, b)), LibUp(std::max(a, b)));
}

bool HasInf(const Interval& x) { return std::isinf(x.lo) || std::isinf(x.hi); }
bool HasZero(const Interval& x) { return x.lo <= 0 && x.hi >= 0; }

// An elementary function that is non-decreasing on the interval.
template <typename F>
Interval Increasing(const Interval& x, F f) {
  if (x.maybe_nan) return Interval::NaN();
  return Make(LibDown(f(x.lo)), LibUp(f(x.hi)));
}
template <typename F>
Interval Decreasing(const Interval& x, F f) {
  if (x.maybe_nan) return Interval::NaN();
  return Make(LibDown(f(x.hi)), LibUp(f(x.lo)));
}

// Whether [x.lo, x.hi] may hold c + k * period for an integer k. Errs towards
// true by 1e-9 periods, which only loosens a bound. REQUIRES: |x| <=
// kPeriodicLimit.
bool HasCritical(const Interval& x, double c, double period) {
  constexpr double kTol = 1e-9;
  const double t0 = (x.lo - c) / period, t1 = (x.hi - c) / period;
  return std::ceil(t0 - kTol) <= t1 + kTol;
}

bool Periodic(const Interval& x, double period) {
  return !x.maybe_nan && !HasInf(x) && std::max(-x.lo, x.hi) <= kPeriodicLimit &&
         x.hi - x.lo < period;
}

Interval ZeroOne() { return Interval::Of(0, 1); }
Interval Bool(bool b) { return Interval::Point(b ? 1 : 0); }

}  // namespace

Interval Interval::Point(double x) { return Make(x, x); }

Interval Hull(const Interval& a, const Interval& b) {
  if (a.maybe_nan || b.maybe_nan) return Interval::NaN();
  return Interval::Of(std::min(a.lo, b.lo), std::max(a.hi, b.hi));
}

Interval operator+(const Interval& a, const Interval& b) {
  if (a.maybe_nan || b.maybe_nan) return Interval::NaN();
  if ((a.lo == -kInf && b.hi == kInf) || (a.hi == kInf && b.lo == -kInf)) return Interval::NaN();
  return Make(Down(a.lo + b.lo), Up(a.hi + b.hi));
}

Interval operator-(const Interval& a) {
  Interval r = Interval::Of(-a.hi, -a.lo);
  r.maybe_nan = a.maybe_nan;
  return r;
}

Interval operator-(const Interval& a, const Interval& b) { return a + (-b); }

Interval operator*(const Interval& a, const Interval& b) {
  if (a.maybe_nan || b.maybe_nan) return Interval::NaN();
  if ((HasZero(a) && HasInf(b)) || (HasZero(b) && HasInf(a))) return Interval::NaN();  // 0 * inf
  const double p[4] = {a.lo * b.lo, a.lo * b.hi, a.hi * b.lo, a.hi * b.hi};
  return Make(Down(*std::min_element(p, p + 4)), Up(*std::max_element(p, p + 4)));
}

Interval operator/(const Interval& a, const Interval& b) {
  if (a.maybe_nan || b.maybe_nan || HasZero(b)) return Interval::NaN();  // x/0 or 0/0
  if (HasInf(a) && HasInf(b)) return Interval::NaN();                    // inf/inf
  const double q[4] = {a.lo / b.lo, a.lo / b.hi, a.hi / b.lo, a.hi / b.hi};
  return Make(Down(*std::min_element(q, q + 4)), Up(*std::max_element(q, q + 4)));
}

Interval Square(const Interval& x) {
  if (x.maybe_nan) return Interval::NaN();
  const double big = std::max(-x.lo, x.hi);
  const double small = HasZero(x) ? 0 : std::min(std::fabs(x.lo), std::fabs(x.hi));
  return Make(std::max(0.0, Down(small * small)), Up(big * big));
}

Interval Cube(const Interval& x) {
  if (x.maybe_nan) return Interval::NaN();
  // (t*t)*t rounds monotonically in t; two roundings, so the library margin.
  return Make(LibDown((x.lo * x.lo) * x.lo), LibUp((x.hi * x.hi) * x.hi));
}

Interval Fourth(const Interval& x) {
  if (x.maybe_nan) return Interval::NaN();
  auto f = [](double t) { return ((t * t) * t) * t; };  // even, monotone in |t|
  const double big = std::max(-x.lo, x.hi);
  const double small = HasZero(x) ? 0 : std::min(std::fabs(x.lo), std::fabs(x.hi));
  return Make(std::max(0.0, LibDown(f(small))), LibUp(f(big)));
}

Interval Pow(const Interval& x, const Interval& y) {
  if (y.IsPoint() && y.lo == 0) return Interval::Point(1);  // pow(anything, 0) = 1
  if (x.maybe_nan || y.maybe_nan) return Interval::NaN();
  auto pow = [](double a, double b) { return math::Pow(a, b); };
  if (y.IsPoint()) {
    const double n = y.lo;
    if (std::isfinite(n) && n == std::floor(n)) {
      // Integer exponent: monotone wherever x keeps its sign, and for odd n > 0.
      const bool odd = std::fmod(n, 2) != 0;
      if (!HasZero(x) || (n > 0 && odd)) return LibMake(pow(x.lo, n), pow(x.hi, n));
      if (n < 0) return Interval::NaN();  // poles of both signs at 0
      return Make(0, LibUp(std::max(pow(x.lo, n), pow(x.hi, n))));
    }
  }
  // Non-integer exponents need x >= 0 (NaN otherwise). On x >= 0, pow is
  // monotone in each argument for the other fixed, so its extremes over the
  // box lie at the corners.
  if (x.lo < 0) return Interval::NaN();
  const double c[4] = {pow(x.lo, y.lo), pow(x.lo, y.hi), pow(x.hi, y.lo), pow(x.hi, y.hi)};
  for (double v : c) {
    if (std::isnan(v)) return Interval::NaN();
  }
  return Make(LibDown(*std::min_element(c, c + 4)), LibUp(*std::max_element(c, c + 4)));
}

Interval Sin(const Interval& x) {
  if (x.maybe_nan || HasInf(x)) return Interval::NaN();  // sin(inf) is NaN
  if (!Periodic(x, 2 * kPi)) return Interval::Of(LibDown(-1), LibUp(1));
  Interval r = LibMake(math::SinCosOf(x.lo).sin, math::SinCosOf(x.hi).sin);
  if (HasCritical(x, kPi / 2, 2 * kPi)) r.hi = LibUp(1);
  if (HasCritical(x, -kPi / 2, 2 * kPi)) r.lo = LibDown(-1);
  return r;
}

Interval Cos(const Interval& x) {
  if (x.maybe_nan || HasInf(x)) return Interval::NaN();
  if (!Periodic(x, 2 * kPi)) return Interval::Of(LibDown(-1), LibUp(1));
  Interval r = LibMake(math::SinCosOf(x.lo).cos, math::SinCosOf(x.hi).cos);
  if (HasCritical(x, 0, 2 * kPi)) r.hi = LibUp(1);
  if (HasCritical(x, kPi, 2 * kPi)) r.lo = LibDown(-1);
  return r;
}

Interval Tan(const Interval& x) {
  if (x.maybe_nan || HasInf(x)) return Interval::NaN();
  if (!Periodic(x, kPi) || HasCritical(x, kPi / 2, kPi)) return Interval::Of(-kInf, kInf);
  return Increasing(x, [](double t) { return math::Tan(t); });
}

Interval Asin(const Interval& x) {
  if (x.lo < -1 || x.hi > 1) return Interval::NaN();
  return Increasing(x, [](double t) { return math::Asin(t); });
}

Interval Acos(const Interval& x) {
  if (x.lo < -1 || x.hi > 1) return Interval::NaN();
  return Decreasing(x, [](double t) { return math::Acos(t); });
}

Interval Atan(const Interval& x) {
  return Increasing(x, [](double t) { return math::Atan(t); });
}

Interval Atan2(const Interval& y, const Interval& x) {
  if (x.maybe_nan || y.maybe_nan) return Interval::NaN();
  if (x.lo > 0 && !HasInf(x) && !HasInf(y)) {
    // On the right half-plane atan2 is monotone in each argument: corners.
    const double c[4] = {math::Atan2(y.lo, x.lo), math::Atan2(y.lo, x.hi), math::Atan2(y.hi, x.lo),
                         math::Atan2(y.hi, x.hi)};
    return Make(LibDown(*std::min_element(c, c + 4)), LibUp(*std::max_element(c, c + 4)));
  }
  return Interval::Of(LibDown(-kPi), LibUp(kPi));
}

Interval Sinh(const Interval& x) {
  return Increasing(x, [](double t) { return math::Sinh(t); });
}

Interval Cosh(const Interval& x) {
  if (x.maybe_nan) return Interval::NaN();
  const double big = math::Cosh(std::max(-x.lo, x.hi));
  const double small = HasZero(x) ? 1 : math::Cosh(std::min(std::fabs(x.lo), std::fabs(x.hi)));
  return Make(LibDown(small), LibUp(big));
}

Interval Tanh(const Interval& x) {
  return Increasing(x, [](double t) { return math::Tanh(t); });
}

Interval Asinh(const Interval& x) {
  return Increasing(x, [](double t) { return math::Asinh(t); });
}

Interval Acosh(const Interval& x) {
  if (x.lo < 1) return Interval::NaN();
  return Increasing(x, [](double t) { return math::Acosh(t); });
}

Interval Atanh(const Interval& x) {
  if (x.lo < -1 || x.hi > 1) return Interval::NaN();
  return Increasing(x, [](double t) { return math::Atanh(t); });
}

Interval Exp(const Interval& x) {
  return Increasing(x, [](double t) { return math::Exp(t); });
}

Interval Log(const Interval& x) {
  if (x.lo < 0) return Interval::NaN();
  return Increasing(x, [](double t) { return math::Log(t); });
}

Interval Log2(const Interval& x) {
  if (x.lo < 0) return Interval::NaN();
  return Increasing(x, [](double t) { return math::Log2(t); });
}

Interval Log10(const Interval& x) {
  if (x.lo < 0) return Interval::NaN();
  return Increasing(x, [](double t) { return math::Log10(t); });
}

Interval Sqrt(const Interval& x) {
  if (x.maybe_nan || x.lo < 0) return Interval::NaN();
  return Make(Down(std::sqrt(x.lo)), Up(std::sqrt(x.hi)));
}

Interval IncreasingImage(const Interval& x, double f_at_lo, double f_at_hi) {
  if (x.maybe_nan) return Interval::NaN();
  return Make(LibDown(f_at_lo), LibUp(f_at_hi));
}

Interval Abs(const Interval& x) {
  if (x.maybe_nan) return Interval::NaN();
  if (x.lo >= 0) return x;
  if (x.hi <= 0) return -x;
  return Interval::Of(0, std::max(-x.lo, x.hi));
}

Interval Sign(const Interval& x) {
  if (x.maybe_nan) return Interval::Of(-1, 1);  // sign(NaN) = 0
  if (x.lo > 0) return Interval::Point(1);
  if (x.hi < 0) return Interval::Point(-1);
  return Interval::Of(x.lo < 0 ? -1 : 0, x.hi > 0 ? 1 : 0);
}

Interval Rint(const Interval& x) {
  if (x.maybe_nan) return Interval::NaN();
  // floor(t + 0.5) rounds monotonically and yields integers: no widening.
  return Make(std::floor(x.lo + 0.5), std::floor(x.hi + 0.5));
}

Interval Min(const Interval& a, const Interval& b) {
  if (a.maybe_nan || b.maybe_nan) return Interval::NaN();
  return Interval::Of(std::min(a.lo, b.lo), std::min(a.hi, b.hi));
}

Interval Max(const Interval& a, const Interval& b) {
  if (a.maybe_nan || b.maybe_nan) return Interval::NaN();
  return Interval::Of(std::max(a.lo, b.lo), std::max(a.hi, b.hi));
}

Truth TruthOf(const Interval& x) {
  if (x.maybe_nan) return Truth::kUnknown;  // NaN is true, but the value may also be 0
  if (x.lo == 0 && x.hi == 0) return Truth::kFalse;
  if (x.lo > 0 || x.hi < 0) return Truth::kTrue;
  return Truth::kUnknown;
}

Interval Less(const Interval& a, const Interval& b) {
  if (a.maybe_nan || b.maybe_nan) return ZeroOne();
  if (a.hi < b.lo) return Bool(true);
  if (a.lo >= b.hi) return Bool(false);
  return ZeroOne();
}

Interval LessEqual(const Interval& a, const Interval& b) {
  if (a.maybe_nan || b.maybe_nan) return ZeroOne();
  if (a.hi <= b.lo) return Bool(true);
  if (a.lo > b.hi) return Bool(false);
  return ZeroOne();
}

Interval Equal(const Interval& a, const Interval& b) {
  if (a.maybe_nan || b.maybe_nan) return ZeroOne();
  if (a.IsPoint() && b.IsPoint() && a.lo == b.lo) return Bool(true);
  if (a.hi < b.lo || b.hi < a.lo) return Bool(false);
  return ZeroOne();
}

Interval NotEqual(const Interval& a, const Interval& b) {
  const Interval e = Equal(a, b);
  return e.IsPoint() ? Bool(e.lo == 0) : ZeroOne();
}

Interval LogicalAnd(const Interval& a, const Interval& b) {
  const Truth ta = TruthOf(a), tb = TruthOf(b);
  if (ta == Truth::kFalse || tb == Truth::kFalse) return Bool(false);
  if (ta == Truth::kTrue && tb == Truth::kTrue) return Bool(true);
  return ZeroOne();
}

Interval LogicalOr(const Interval& a, const Interval& b) {
  const Truth ta = TruthOf(a), tb = TruthOf(b);
  if (ta == Truth::kTrue || tb == Truth::kTrue) return Bool(true);
  if (ta == Truth::kFalse && tb == Truth::kFalse) return Bool(false);
  return ZeroOne();
}

}  // namespace sfc
