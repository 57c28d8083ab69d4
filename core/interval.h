// Rigorous interval arithmetic over doubles, for provable bounds of surface
// patches (Surface::Bound) and of user expressions.
//
// An Interval [lo, hi] encloses every double that the same computation, done
// in ordinary round-to-nearest double arithmetic with the project's
// elementary functions (core/vector_math.h: SLEEF's, as the double code
// uses) or the C library's, yields for any inputs inside the input
// intervals; for the continuous operations it also encloses the exact real
// result (rint, sign and the comparisons enclose what the double code
// computes, which is what sampling needs). Each operation computes its end
// points in round-to-nearest and then widens them outward: one ulp
// (std::nextafter) after the correctly rounded operations (+ - * / sqrt), and
// a relative margin of kLibmMargin after elementary functions, whose results
// SLEEF and glibc document to within a few ulp and which need not be monotone
// to the last bit. The end points come from core/vector_math.h's functions,
// not the C library's (whose FMA code paths differ in the last bit between
// CPUs), so a bound is the same bits on every machine: the tree's
// hidden-mass check compares bounds, and its trees must not depend on the
// CPU.
//
// NaN is tracked explicitly: `maybe_nan` says the computation may yield NaN
// (sqrt of a negative, 0 * inf, inf - inf, sin(inf), pow of a negative to a
// fractional power, ...); such an interval is the whole line and stays so
// through every later operation except those that turn NaN into an ordinary
// value (comparisons, sign), which then return every value they could.
// Infinite end points are ordinary values (1/0 = inf in double arithmetic).
//
// Value type; all functions are pure and thread-safe.
#ifndef SFCSAMPLER_CORE_INTERVAL_H_
#define SFCSAMPLER_CORE_INTERVAL_H_

#include <limits>

namespace sfc {

struct Interval {
  double lo = 0, hi = 0;
  bool maybe_nan = false;

  static Interval Point(double x);  // [x, x], or the NaN interval if x is NaN
  static Interval Of(double lo, double hi) { return {lo, hi, false}; }
  // The whole extended line, possibly NaN.
  static Interval NaN() {
    return {-std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
            true};
  }
  bool IsPoint() const { return !maybe_nan && lo == hi; }
  bool Contains(double x) const { return maybe_nan || (x >= lo && x <= hi); }
};

// Relative outward margin after elementary functions (about 450 ulp).
inline constexpr double kLibmMargin = 1e-13;

// The smallest interval holding both.
Interval Hull(const Interval& a, const Interval& b);

Interval operator+(const Interval& a, const Interval& b);
Interval operator-(const Interval& a, const Interval& b);
Interval operator*(const Interval& a, const Interval& b);
Interval operator/(const Interval& a, const Interval& b);
Interval operator-(const Interval& a);

// x*x, (x*x)*x and ((x*x)*x)*x evaluated in that order, without the
// dependency loss of multiplying intervals (x in [-1,1] gives [0,1] squared).
Interval Square(const Interval& x);
Interval Cube(const Interval& x);
Interval Fourth(const Interval& x);

// Pow(x, y) (math::Pow, the C library's pow within 1 ulp).
Interval Pow(const Interval& x, const Interval& y);

// The elementary functions of the same name (core/vector_math.h).
Interval Sin(const Interval& x);
Interval Cos(const Interval& x);
Interval Tan(const Interval& x);
Interval Asin(const Interval& x);
Interval Acos(const Interval& x);
Interval Atan(const Interval& x);
Interval Atan2(const Interval& y, const Interval& x);
Interval Sinh(const Interval& x);
Interval Cosh(const Interval& x);
Interval Tanh(const Interval& x);
Interval Asinh(const Interval& x);
Interval Acosh(const Interval& x);
Interval Atanh(const Interval& x);
Interval Exp(const Interval& x);
Interval Log(const Interval& x);
Interval Log2(const Interval& x);
Interval Log10(const Interval& x);
Interval Sqrt(const Interval& x);

// The image of x under a function computed with library calls or several
// roundings that is non-decreasing on x in exact arithmetic, given its
// computed values at x.lo and x.hi: those values widened by kLibmMargin.
Interval IncreasingImage(const Interval& x, double f_at_lo, double f_at_hi);

// (x >= 0) ? x : -x.
Interval Abs(const Interval& x);
// -1, 0 or 1 as x < 0, x == 0 (or NaN), x > 0.
Interval Sign(const Interval& x);
// floor(x + 0.5).
Interval Rint(const Interval& x);
// std::min(a, b) = (b < a) ? b : a, and std::max(a, b) = (a < b) ? b : a.
Interval Min(const Interval& a, const Interval& b);
Interval Max(const Interval& a, const Interval& b);

// The truth of a value used as a condition (non-zero, NaN included, is true).
enum class Truth { kFalse, kTrue, kUnknown };
Truth TruthOf(const Interval& x);

// Comparisons and logic as 1.0 (true) or 0.0 (false): [1,1], [0,0] or [0,1].
Interval Less(const Interval& a, const Interval& b);          // a < b
Interval LessEqual(const Interval& a, const Interval& b);     // a <= b
Interval Equal(const Interval& a, const Interval& b);         // a == b
Interval NotEqual(const Interval& a, const Interval& b);      // a != b
Interval LogicalAnd(const Interval& a, const Interval& b);    // a && b
Interval LogicalOr(const Interval& a, const Interval& b);     // a || b

}  // namespace sfc

#endif  // SFCSAMPLER_CORE_INTERVAL_H_
