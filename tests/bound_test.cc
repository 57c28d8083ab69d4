// Provable bounds: interval operations enclose every point value, and each
// surface's Bound holds every point Point (and Jet) computes on a cell.
#include <cmath>
#include <random>
#include <string>

#include "catalog/catalog.h"
#include "core/interval.h"
#include "core/surface.h"
#include "gtest/gtest.h"

namespace sfc {
namespace {

bool Inside(const Vec3& p, const Box3& b) {
  return p.x >= b.lo.x && p.x <= b.hi.x && p.y >= b.lo.y && p.y <= b.hi.y && p.z >= b.lo.z &&
         p.z <= b.hi.z;
}

// A random interval: widths from 1e-12 to 20, centres from -10 to 10.
Interval RandomInterval(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double w = std::pow(10.0, -12 + 13.3 * unit(rng));
  const double c = -10 + 20 * unit(rng);
  return Interval::Of(c - w / 2, c + w / 2);
}

double PointIn(const Interval& x, std::mt19937_64& rng, int k) {
  if (k == 0) return x.lo;
  if (k == 1) return x.hi;
  return std::clamp(x.lo + (x.hi - x.lo) * std::uniform_real_distribution<double>(0, 1)(rng),
                    x.lo, x.hi);
}

void ExpectEncloses(const Interval& bound, double value, const std::string& what) {
  if (std::isnan(value)) {
    EXPECT_TRUE(bound.maybe_nan) << what << " may be NaN";
  } else {
    EXPECT_TRUE(bound.Contains(value))
        << what << " = " << value << " outside [" << bound.lo << ", " << bound.hi << "]";
  }
}

TEST(Interval, UnaryFunctionsEncloseTheirValues) {
  struct Unary {
    const char* name;
    Interval (*bound)(const Interval&);
    double (*f)(double);
  };
  const Unary kUnary[] = {
      {"sin", Sin, [](double x) { return std::sin(x); }},
      {"cos", Cos, [](double x) { return std::cos(x); }},
      {"tan", Tan, [](double x) { return std::tan(x); }},
      {"asin", Asin, [](double x) { return std::asin(x); }},
      {"acos", Acos, [](double x) { return std::acos(x); }},
      {"atan", Atan, [](double x) { return std::atan(x); }},
      {"sinh", Sinh, [](double x) { return std::sinh(x); }},
      {"cosh", Cosh, [](double x) { return std::cosh(x); }},
      {"tanh", Tanh, [](double x) { return std::tanh(x); }},
      {"asinh", Asinh, [](double x) { return std::asinh(x); }},
      {"acosh", Acosh, [](double x) { return std::acosh(x); }},
      {"atanh", Atanh, [](double x) { return std::atanh(x); }},
      {"exp", Exp, [](double x) { return std::exp(x); }},
      {"log", Log, [](double x) { return std::log(x); }},
      {"log2", Log2, [](double x) { return std::log2(x); }},
      {"log10", Log10, [](double x) { return std::log10(x); }},
      {"sqrt", Sqrt, [](double x) { return std::sqrt(x); }},
      {"abs", Abs, [](double x) { return x >= 0 ? x : -x; }},
      {"sign", Sign, [](double x) { return x < 0 ? -1.0 : x > 0 ? 1.0 : 0.0; }},
      {"rint", Rint, [](double x) { return std::floor(x + 0.5); }},
      {"square", Square, [](double x) { return x * x; }},
      {"cube", Cube, [](double x) { return (x * x) * x; }},
      {"fourth", Fourth, [](double x) { return ((x * x) * x) * x; }},
      {"neg", [](const Interval& x) { return -x; }, [](double x) { return -x; }},
  };
  std::mt19937_64 rng(3);
  for (const Unary& f : kUnary) {
    for (int i = 0; i < 3000; ++i) {
      Interval x = RandomInterval(rng);
      if (i % 3 == 0) x = Interval::Of(x.lo / 10, x.hi / 10);  // near the domains of asin etc.
      const Interval b = f.bound(x);
      for (int k = 0; k < 20; ++k) {
        const double p = PointIn(x, rng, k);
        ExpectEncloses(b, f.f(p), std::string(f.name) + "(" + std::to_string(p) + ")");
      }
    }
  }
}

TEST(Interval, BinaryOperationsEncloseTheirValues) {
  struct Binary {
    const char* name;
    Interval (*bound)(const Interval&, const Interval&);
    double (*f)(double, double);
  };
  const Binary kBinary[] = {
      {"+", [](const Interval& a, const Interval& b) { return a + b; },
       [](double a, double b) { return a + b; }},
      {"-", [](const Interval& a, const Interval& b) { return a - b; },
       [](double a, double b) { return a - b; }},
      {"*", [](const Interval& a, const Interval& b) { return a * b; },
       [](double a, double b) { return a * b; }},
      {"/", [](const Interval& a, const Interval& b) { return a / b; },
       [](double a, double b) { return a / b; }},
      {"pow", Pow, [](double a, double b) { return std::pow(a, b); }},
      {"atan2", Atan2, [](double a, double b) { return std::atan2(a, b); }},
      {"min", Min, [](double a, double b) { return b < a ? b : a; }},
      {"max", Max, [](double a, double b) { return a < b ? b : a; }},
  };
  std::mt19937_64 rng(4);
  for (const Binary& f : kBinary) {
    for (int i = 0; i < 3000; ++i) {
      Interval a = RandomInterval(rng), b = RandomInterval(rng);
      if (i % 4 == 0) b = Interval::Point(std::round(b.lo));  // integer exponents, 0 divisors
      if (i % 4 == 1) b = Interval::Point(b.lo / 3);          // fractional exponents
      if (i % 5 == 0) a = Interval::Of(std::fabs(a.lo) / 5, std::fabs(a.lo) / 5 + a.hi - a.lo);
      const Interval r = f.bound(a, b);
      for (int k = 0; k < 20; ++k) {
        const double x = PointIn(a, rng, k % 2), y = PointIn(b, rng, k / 2);
        ExpectEncloses(r, f.f(x, y),
                       std::to_string(x) + " " + f.name + " " + std::to_string(y));
      }
    }
  }
}

TEST(Interval, WideAndSingularCasesAreSafe) {
  // sin over a period and over extrema.
  EXPECT_LE(Sin(Interval::Of(0, 7)).lo, -1);
  EXPECT_GE(Sin(Interval::Of(1, 2)).hi, 1);
  EXPECT_LE(Cos(Interval::Of(3, 3.5)).lo, -1);
  // Division by an interval holding 0 is unbounded.
  const Interval q = Interval::Point(1) / Interval::Of(-1, 1);
  EXPECT_TRUE(q.maybe_nan);
  // A fractional power of a possibly negative base may be NaN.
  EXPECT_TRUE(Pow(Interval::Of(-1, 1), Interval::Point(0.5)).maybe_nan);
  // NaN survives min and a comparison of NaN is undecided.
  const Interval nan = Sqrt(Interval::Of(-1, 1));
  EXPECT_TRUE(Min(nan, Interval::Point(1)).maybe_nan);
  EXPECT_EQ(TruthOf(Less(nan, Interval::Point(2))), Truth::kUnknown);
  // Results are widened: [0.1] + [0.2] holds both 0.1 + 0.2 and 0.3.
  const Interval s = Interval::Point(0.1) + Interval::Point(0.2);
  EXPECT_TRUE(s.Contains(0.1 + 0.2) && s.Contains(0.3));
  EXPECT_LT(s.lo, s.hi);
}

const char* kSurfaces[] = {
    "plane",
    "sphere:r=2",
    "torus:R=1;r=0.4",
    "monkey_saddle",
    "eight",
    "whitney",
    "superellipsoid",
    "superellipsoid:reparam=1",
    "superellipsoid:e=3",
    "expr:x=u;y=v;z=sin(8*_pi*u)",
    "expr:x=sin(u)*cos(v);y=sin(u)*sin(v);z=cos(u);u1=_pi;v1=2*_pi",
    "expr:x=u*cos(v);y=u*sin(v);z=u < 0.5 ? u^2 : sqrt(u) - v/3;u0=0.1;v1=6",
    "expr:x=exp(u)*cos(3*v);y=atan2(v - 0.5, u + 0.1);z=max(u, v)^3 - abs(u - v)",
    "expr:x=u;y=v;z=tan(u) / (1 + v^2) + log(1 + u*v)",
};

// Random cells of random sizes (dyadic and 3-adic, as the curves make them,
// and arbitrary ones): every point of a cell maps inside the cell's bound.
TEST(SurfaceBound, HoldsEveryPointOfTheCell) {
  std::mt19937_64 rng(21);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (const char* spec : kSurfaces) {
    auto made = MakeSurface(spec);
    ASSERT_TRUE(made.ok()) << spec << ": " << made.status();
    const Surface& s = *made->surface;
    for (int cell = 0; cell < 600; ++cell) {
      double h;
      if (cell % 3 == 0) {
        h = std::ldexp(1.0, -static_cast<int>(unit(rng) * 20));
      } else if (cell % 3 == 1) {
        h = std::pow(3.0, -static_cast<int>(unit(rng) * 12));
      } else {
        h = unit(rng);
      }
      const double u0 = std::floor(unit(rng) / h) * h, v0 = std::floor(unit(rng) / h) * h;
      const double u1 = std::min(1.0, u0 + h), v1 = std::min(1.0, v0 + h);
      const std::optional<Box3> box = s.Bound(u0, u1, v0, v1);
      ASSERT_TRUE(box.has_value()) << spec;
      for (int k = 0; k < 40; ++k) {
        const double u = k < 2 ? (k ? u1 : u0) : u0 + (u1 - u0) * unit(rng);
        const double v = k < 2 ? (k ? v1 : v0) : v0 + (v1 - v0) * unit(rng);
        const Vec3 p = s.Point(u, v);
        EXPECT_TRUE(Inside(p, *box)) << spec << " at " << u << "," << v << " in cell [" << u0
                                     << "," << u1 << "] x [" << v0 << "," << v1 << "]";
        EXPECT_EQ(s.Jet(u, v, 1).p, p) << spec;
      }
    }
  }
}

// On a small cell the bound is close to the patch: per axis at most three
// times the spread of the cell's points (plus rounding).
TEST(SurfaceBound, IsTightOnSmallCells) {
  for (const char* spec : kSurfaces) {
    auto made = MakeSurface(spec);
    ASSERT_TRUE(made.ok());
    const Surface& s = *made->surface;
    const double h = 1.0 / 1024, u0 = 0.3, v0 = 0.35;
    const Box3 box = *s.Bound(u0, u0 + h, v0, v0 + h);
    Vec3 lo = s.Point(u0, v0), hi = lo;
    for (int i = 0; i <= 16; ++i) {
      for (int j = 0; j <= 16; ++j) {
        const Vec3 p = s.Point(u0 + i * h / 16, v0 + j * h / 16);
        lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
        hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
      }
    }
    const Vec3 spread = hi - lo, size = box.hi - box.lo;
    EXPECT_LE(size.x, 3 * spread.x + 1e-9) << spec;
    EXPECT_LE(size.y, 3 * spread.y + 1e-9) << spec;
    EXPECT_LE(size.z, 3 * spread.z + 1e-9) << spec;
  }
}

class NoBoundSurface final : public Surface {
 public:
  Vec3 Point(double u, double v) const override { return {u, v, u * v}; }
};

TEST(SurfaceBound, DefaultIsUnknown) {
  EXPECT_FALSE(NoBoundSurface().Bound(0, 1, 0, 1).has_value());
}

}  // namespace
}  // namespace sfc
