// Samples beside a singular line follow the mass piled against it (paper
// Sect. 5.3; docs/ALGORITHM.md, "Singular parameterisations"): the counts in
// thin strips beside the superellipsoid's singular lines match the exact
// fractions, for an area element that blows up (e = 1/3, 1/4) and one that
// vanishes (e = 2) on the lines. The exact fractions come from this file's
// own quadrature of a closed-form area element (the substitution t = w^3
// removes the singularity; the evaluation's Gauss rule), sharing nothing
// with the sampler but the surface's definition. Coarse histograms cannot
// see this error: every leaf's total is right, only the thin strips show it.
#include <cmath>
#include <functional>
#include <vector>

#include "evaluation/gauss_legendre.h"
#include "gtest/gtest.h"
#include "tests/test_util.h"

namespace sfc {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Composite 16-point Gauss-Legendre rule with `panels` panels on [a, b].
double Integrate(const std::function<double(double)>& f, double a, double b, int panels) {
  const GaussRule& rule = GaussLegendreRule(16);
  double sum = 0;
  const double h = (b - a) / panels;
  for (int p = 0; p < panels; ++p) {
    for (int i = 0; i < 16; ++i) sum += rule.w[i] * f(a + (p + rule.x[i]) * h);
  }
  return sum * h;
}

// |f_a x f_b| of the superellipsoid (cos^e a cos^e b, cos^e a sin^e b,
// sin^e a) for a, b in (0, pi/2), written out from its definition.
double AreaElement(double e, double a, double b) {
  const double ca = std::cos(a), sa = std::sin(a), cb = std::cos(b), sb = std::sin(b);
  const double Ca = std::pow(ca, e), dCa = -e * std::pow(ca, e - 1) * sa;
  const double dSa = e * std::pow(sa, e - 1) * ca;
  const double Cb = std::pow(cb, e), Sb = std::pow(sb, e);
  const double dCb = -e * std::pow(cb, e - 1) * sb, dSb = e * std::pow(sb, e - 1) * cb;
  const double cross = Cb * dSb - Sb * dCb;
  return Ca * std::sqrt(dSa * dSa * (dSb * dSb + dCb * dCb) + dCa * dCa * cross * cross);
}

// int_0^{pi/2} g(t) dt for g singular at both ends like a power: each half
// with the substitution t = w^3 from its end.
double Quarter(const std::function<double(double)>& g) {
  const double c = std::cbrt(kPi / 4);
  return Integrate([&](double w) { return g(w * w * w) * 3 * w * w; }, 0, c, 6) +
         Integrate([&](double w) { return g(kPi / 2 - w * w * w) * 3 * w * w; }, 0, c, 6);
}

// The exact fraction of the surface's area within unit parameter distance
// d of the longitude lines (v in {0, 1/4, 1/2, 3/4, 1}; b = 2 pi v) or of the
// equator (u = 1/2; a = pi u - pi/2). By symmetry one octant suffices: a and
// b in [0, pi/2], `across` the mass density integrated across the other.
struct Fractions {
  double e;
  double Longitude(double d) const {
    // b in [0, pi/2] has a longitude line at each end, mirror images.
    auto across = [&](double b) { return Quarter([&](double a) { return AreaElement(e, a, b); }); };
    return 2 * Near(across, 2 * kPi * d);
  }
  double Equator(double d) const {
    auto across = [&](double a) { return Quarter([&](double b) { return AreaElement(e, a, b); }); };
    return Near(across, kPi * d);
  }
  // The share of [0, pi/2] of the mass within distance `t` of its start.
  static double Near(const std::function<double(double)>& across, double t) {
    auto near = [&](double limit) {
      return Integrate([&](double w) { return across(w * w * w) * 3 * w * w; }, 0, std::cbrt(limit),
                       6);
    };
    return near(t) / Quarter(across);
  }
};

struct Band {
  double lo, hi;
};

// Samples of the default superellipsoid (no reparameterisation) with
// exponent e, N samples, seed 5, uniform density.
SampleBatch Samples(double e, uint64_t n, CurveType curve = CurveType::kHilbert) {
  CurveTreeOptions options;
  options.curve = curve;
  const auto setup =
      testing::MakeSetup("superellipsoid:e=" + std::to_string(e), "uniform", n, options);
  return testing::Collect(testing::MakeSampler(setup, SequenceKind::kJittered, n, 5), 0, n, {}, {},
                          1 << 16);
}

// Counts within max(2 %, 2 sqrt(exact)) of the exact count, band by band.
void ExpectStripsMatch(const std::vector<double>& distance, const std::vector<Band>& bands,
                       const std::function<double(double)>& fraction, const char* line) {
  const double n = static_cast<double>(distance.size());
  for (const Band& b : bands) {
    const double exact = (fraction(b.hi) - (b.lo > 0 ? fraction(b.lo) : 0)) * n;
    double count = 0;
    for (double t : distance) count += t >= b.lo && t < b.hi;
    EXPECT_NEAR(count, exact, std::max(0.02 * exact, 2 * std::sqrt(exact)))
        << line << " band [" << b.lo << ", " << b.hi << ")";
  }
}

std::vector<double> LongitudeDistances(const SampleBatch& s) {
  std::vector<double> d(s.size());
  for (size_t i = 0; i < s.size(); ++i) d[i] = std::fabs(s.v[i] * 4 - std::round(s.v[i] * 4)) / 4;
  return d;
}

std::vector<double> EquatorDistances(const SampleBatch& s) {
  std::vector<double> d(s.size());
  for (size_t i = 0; i < s.size(); ++i) d[i] = std::fabs(s.u[i] - 0.5);
  return d;
}

TEST(SingularPlacement, TheReferenceGivesTheOctahedronItsArea) {
  // e = 2 is the octahedron |x| + |y| + |z| = 1: area 4 sqrt(3), one octant sqrt(3)/2.
  const double octant = Quarter([](double a) {
    return Quarter([a](double b) { return AreaElement(2, a, b); });
  });
  EXPECT_NEAR(octant, std::sqrt(3.0) / 2, 1e-9);
}

TEST(SingularPlacement, StripsBesideLinesWhereTheAreaElementBlowsUp) {
  const std::vector<Band> bands = {{0, 1e-4}, {1e-4, 1e-3}, {1e-3, 2e-3}, {2e-3, 1e-2}};
  for (double e : {1.0 / 3, 0.25}) {
    const SampleBatch s = Samples(e, 200000);
    ASSERT_EQ(s.size(), 200000u);
    const Fractions f{e};
    ExpectStripsMatch(LongitudeDistances(s), bands, [&](double d) { return f.Longitude(d); },
                      e > 0.3 ? "e = 1/3, longitude" : "e = 1/4, longitude");
    ExpectStripsMatch(EquatorDistances(s), bands, [&](double d) { return f.Equator(d); },
                      e > 0.3 ? "e = 1/3, equator" : "e = 1/4, equator");
  }
}

TEST(SingularPlacement, StripsBesideLinesThroughTheCells) {
  // On the 3 x 3 curves the lines u = 1/2 and v = 1/4, 1/2, 3/4 cross the
  // cells instead of bounding them.
  const std::vector<Band> bands = {{0, 1e-4}, {1e-4, 1e-3}, {1e-3, 2e-3}, {2e-3, 1e-2}};
  const SampleBatch s = Samples(1.0 / 3, 200000, CurveType::kPeano);
  const Fractions f{1.0 / 3};
  ExpectStripsMatch(LongitudeDistances(s), bands, [&](double d) { return f.Longitude(d); },
                    "Peano, longitude");
  ExpectStripsMatch(EquatorDistances(s), bands, [&](double d) { return f.Equator(d); },
                    "Peano, equator");
}

TEST(SingularPlacement, StripsBesideLinesWhereTheAreaElementVanishes) {
  // Few samples lie near these lines: a million, in two wide bands.
  const SampleBatch s = Samples(2, 1000000);
  const Fractions f{2};
  ExpectStripsMatch(LongitudeDistances(s), {{0, 1e-3}, {1e-3, 1e-2}},
                    [&](double d) { return f.Longitude(d); }, "e = 2, longitude");
  ExpectStripsMatch(EquatorDistances(s), {{0, 1e-3}, {1e-3, 1e-2}},
                    [&](double d) { return f.Equator(d); }, "e = 2, equator");
}

}  // namespace
}  // namespace sfc
