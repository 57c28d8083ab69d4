// The discrepancy estimators against brute force on small exact cases, their
// area formulas against numeric integration, and the defining properties of
// the reference sets.
#include "evaluation/discrepancy.h"

#include <cmath>
#include <set>

#include "base/counter_hash.h"
#include "evaluation/reference_sets.h"
#include "gtest/gtest.h"

namespace sfc {
namespace {

constexpr double kPi = 3.14159265358979323846;

std::vector<Point2> SmallSet(int n, uint64_t seed) { return RandomSquare(n, seed); }

TEST(StarDiscrepancy, EqualsTheExactSupForSmallSets) {
  for (int n : {1, 2, 5, 17, 40}) {
    const auto pts = SmallSet(n, n);
    // Brute force: every box corner from the coordinates and 1, open and closed.
    std::vector<double> as{1.0}, bs{1.0};
    for (const auto& p : pts) as.push_back(p.x), bs.push_back(p.y);
    double exact = 0;
    for (double a : as) {
      for (double b : bs) {
        int open = 0, closed = 0;
        for (const auto& p : pts) {
          open += p.x < a && p.y < b;
          closed += p.x <= a && p.y <= b;
        }
        exact = std::max({exact, std::fabs(static_cast<double>(open) / n - a * b),
                          std::fabs(static_cast<double>(closed) / n - a * b)});
      }
    }
    EXPECT_DOUBLE_EQ(StarDiscrepancy(pts, 1000), exact) << n;
    // With fewer corners it is a lower bound.
    EXPECT_LE(StarDiscrepancy(pts, 4), exact);
  }
  // One point at the centre: the box [0,1/2]^2 holds it all but has area 1/4.
  EXPECT_DOUBLE_EQ(StarDiscrepancy({{0.5, 0.5}}), 0.75);
}

TEST(QuarterDiscDiscrepancy, EqualsBruteForceOverRadii) {
  for (int n : {1, 3, 20, 60}) {
    const auto pts = SmallSet(n, 100 + n);
    double exact = 0;
    for (int k = 1; k <= 20000; ++k) {
      const double r = std::sqrt(2.0) * k / 20000;
      int inside = 0;
      for (const auto& p : pts) inside += p.x * p.x + p.y * p.y < r * r;
      exact = std::max(exact, std::fabs(static_cast<double>(inside) / n - QuarterDiscArea(r)));
    }
    const double estimate = QuarterDiscDiscrepancy(pts);
    EXPECT_GE(estimate, exact - 1e-12) << n;          // the estimator sees every radius
    EXPECT_LE(estimate, exact + 2e-4) << n;           // the scan misses at most a sliver
  }
}

TEST(TriangleDiscrepancy, EqualsBruteForceOverItsFamily) {
  const int grid = 16;
  for (int n : {1, 7, 50}) {
    const auto pts = SmallSet(n, 200 + n);
    double brute = 0;
    for (int i = 0; i < grid; ++i) {
      for (int j = 0; j < grid; ++j) {
        const double a = (i + 0.5) / grid * 2.5, b = (j + 0.5) / grid * 2.5;
        int inside = 0;
        for (const auto& p : pts) inside += p.x / a + p.y / b < 1;
        brute = std::max(brute,
                         std::fabs(static_cast<double>(inside) / n - AnchoredTriangleArea(a, b)));
      }
    }
    EXPECT_NEAR(TriangleDiscrepancy(pts, grid), brute, 1e-12) << n;
  }
}

TEST(AreaFormulas, MatchNumericIntegration) {
  const int m = 2000;
  for (auto [a, b] : {std::pair{0.5, 0.7}, {1.5, 0.6}, {0.4, 2.0}, {1.8, 1.6}, {2.4, 2.4}}) {
    double inside = 0;
    for (int i = 0; i < m; ++i) {
      for (int j = 0; j < m; ++j) inside += (i + 0.5) / m / a + (j + 0.5) / m / b < 1;
    }
    EXPECT_NEAR(AnchoredTriangleArea(a, b), inside / (m * m), 2e-3) << a << " " << b;
  }
  for (double r : {0.3, 1.0, 1.2, 1.4}) {
    double inside = 0;
    for (int i = 0; i < m; ++i) {
      for (int j = 0; j < m; ++j) {
        const double x = (i + 0.5) / m, y = (j + 0.5) / m;
        inside += x * x + y * y < r * r;
      }
    }
    EXPECT_NEAR(QuarterDiscArea(r), inside / (m * m), 2e-3) << r;
  }
}

TEST(SphericalTriangleDiscrepancy, GirardAreasMatchWhereUniformPointsFall) {
  // Many random points: every triangle's fraction is within a few sigma.
  const auto pts = RandomSphere(200000, 3);
  const double d = SphericalTriangleDiscrepancy(pts, 64, 5);
  EXPECT_LT(d, 5 * 0.5 / std::sqrt(200000.0));
  // A single point cannot be within any triangle's fraction of 0 or 1 by less
  // than the largest (smallest) triangle area: D is large.
  EXPECT_GT(SphericalTriangleDiscrepancy({{0, 0, 1}}, 64, 5), 0.1);
}

TEST(ParameterRectDiscrepancy, IsZeroForOnePointPerCellOfAUniformDensity) {
  const int g = 32;
  std::vector<Point2> pts;
  for (int i = 0; i < g; ++i) {
    for (int j = 0; j < g; ++j) pts.push_back({(i + 0.5) / g, (j + 0.5) / g});
  }
  auto uniform = [](double, double, double h) { return h * h; };
  EXPECT_NEAR(ParameterRectDiscrepancy(pts, uniform, g), 0.0, 1e-12);
  // With density u + v the same points are off by the density's slope.
  auto linear = [](double u0, double v0, double h) { return h * h * (u0 + v0 + h); };
  EXPECT_GT(ParameterRectDiscrepancy(pts, linear, g), 0.1);
}

TEST(ReferenceSets, SobolIsA02SequenceInBase2) {
  for (int m : {4, 7, 10}) {
    const uint64_t n = uint64_t{1} << m;
    const auto pts = SobolSquare(n);
    for (int k = 0; k <= m; ++k) {
      std::set<std::pair<uint64_t, uint64_t>> cells;
      for (const auto& p : pts) {
        cells.insert(
            {static_cast<uint64_t>(p.x * (1 << k)), static_cast<uint64_t>(p.y * (1 << (m - k)))});
      }
      EXPECT_EQ(cells.size(), n) << "m " << m << " k " << k;
    }
  }
}

TEST(ReferenceSets, JitteredPutsOnePointInEachEqualAreaStratum) {
  for (uint64_t n : {16u, 24u, 1000u}) {
    const auto pts = JitteredSquare(n, 1);
    ASSERT_EQ(pts.size(), n);
    // The strata: floor(sqrt n) rows, the first n % rows of them one cell
    // longer, each row as tall as its share of the n equal-area cells.
    const uint64_t rows = static_cast<uint64_t>(std::sqrt(static_cast<double>(n)));
    std::set<std::pair<uint64_t, uint64_t>> occupied;
    double y0 = 0;
    for (uint64_t r = 0; r < rows; ++r) {
      const uint64_t cells = n / rows + (r < n % rows ? 1 : 0);
      const double height = static_cast<double>(cells) / n;
      for (const auto& p : pts) {
        if (p.y >= y0 && p.y < y0 + height)
          occupied.insert({r, static_cast<uint64_t>(p.x * cells)});
      }
      y0 += height;
    }
    EXPECT_EQ(occupied.size(), n) << "every stratum holds exactly one of the n points";
  }
}

TEST(ReferenceSets, SpherePointsAreUnitVectors) {
  for (const auto& set : {RandomSphere(1000, 1), HammersleySphere(1000), FibonacciSphere(1000)}) {
    for (const Vec3& p : set) ASSERT_NEAR(Norm(p), 1.0, 1e-12);
  }
}

}  // namespace
}  // namespace sfc
