// The sample-anchored box discrepancy (evaluation/box_discrepancy.h): its
// reference against exact areas, and that it sees an error confined to
// strips of width 2e-3 beside singular lines, which a measure on a fixed
// 256 x 256 grid cannot see.
#include "evaluation/box_discrepancy.h"

#include <cmath>
#include <random>

#include "core/builtin_surfaces.h"
#include "evaluation/discrepancy.h"
#include "evaluation/reference_measure.h"
#include "evaluation/superellipsoid_exact.h"
#include "gtest/gtest.h"

namespace sfc {
namespace {

constexpr double kPi = 3.14159265358979323846;

TEST(GradedBoxMeasure, ExactAreas) {
  auto uniform = MakeUniformDensity();
  std::shared_ptr<const Surface> spheres[] = {MakeSphere(1), MakeSuperellipsoid(1, false)};
  for (const auto& s : spheres) {
    auto lines = DetectSingularLines(*s, *uniform);
    ASSERT_TRUE(lines.ok());
    auto m = GradedBoxMeasure::Build(*s, *uniform, *lines, {0.123, 0.5}, {0.77}, 64);
    ASSERT_TRUE(m.ok());
    EXPECT_NEAR(m->total(), 4 * kPi, 1e-11);
  }
  auto torus = MakeTorus(1, 0.25);
  auto m = GradedBoxMeasure::Build(*torus, *uniform, {}, {}, {}, 32);
  ASSERT_TRUE(m.ok());
  EXPECT_NEAR(m->total(), 4 * kPi * kPi * 0.25, 1e-11);
}

TEST(GradedBoxMeasure, DetectsNoLinesOnASmoothSurface) {
  auto uniform = MakeUniformDensity();
  auto lines = DetectSingularLines(*MakeTorus(1, 0.25), *uniform);
  ASSERT_TRUE(lines.ok());
  EXPECT_TRUE(lines->u.empty());
  EXPECT_TRUE(lines->v.empty());
  auto r = DetectSingularLines(*MakeSuperellipsoid(1.0 / 3, true), *uniform);
  ASSERT_TRUE(r.ok());
  EXPECT_TRUE(r->v.empty()) << "the power law leaves no longitude line";
}

// i.i.d. points with density dA on the superellipsoid e, by rejection in
// coordinates where the density is bounded (angle = (pi/2) g(s), g(s) =
// s^4 / (s^4 + (1-s)^4)), in the built-in's unit parameters.
std::vector<Point2> ExactPoints(double e, size_t n, uint64_t seed) {
  auto g = [](double s, double* dg) {
    const double p = std::pow(s, 4), q = std::pow(1 - s, 4);
    *dg = 4 * (std::pow(s, 3) * q + p * std::pow(1 - s, 3)) / ((p + q) * (p + q));
    return p / (p + q);
  };
  auto rho = [&](double s, double t) {
    double ds, dt;
    const double a = kPi / 2 * g(s, &ds), b = kPi / 2 * g(t, &dt);
    return SuperellipsoidAreaElement(e, a, b) * ds * dt;
  };
  double peak = 0;
  for (int i = 1; i < 400; ++i) {
    for (int j = 1; j < 400; ++j) peak = std::max(peak, rho(i / 400.0, j / 400.0));
  }
  peak *= 1.3;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uni(0, 1);
  std::vector<Point2> out;
  while (out.size() < n) {
    const double s = uni(rng), t = uni(rng);
    if (uni(rng) * peak >= rho(s, t)) continue;
    double d;
    const double a = kPi / 2 * g(s, &d), b = kPi / 2 * g(t, &d);
    const int quadrant = static_cast<int>(uni(rng) * 4);
    const double lat = uni(rng) < 0.5 ? a : -a;
    out.push_back({lat / kPi + 0.5, (quadrant * (kPi / 2) + b) / (2 * kPi)});
  }
  return out;
}

// The points within `width` (unit v) of a longitude line, spread evenly in
// parameter over that band on their side: every band keeps its count, so
// coarse histograms agree, but the mass piled against the line is lost.
std::vector<Point2> SpreadBesideLines(std::vector<Point2> pts, double width, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uni(0, 1);
  for (Point2& p : pts) {
    const double line = std::round(p.y * 4) / 4;
    if (std::fabs(p.y - line) < width) p.y = line + (p.y > line ? 1 : -1) * width * uni(rng);
  }
  return pts;
}

TEST(SampleAnchoredBoxDiscrepancy, SeesTheErrorBesideTheLines) {
  const double e = 1.0 / 3;
  auto s = MakeSuperellipsoid(e, false);
  auto uniform = MakeUniformDensity();
  auto lines = DetectSingularLines(*s, *uniform);
  ASSERT_TRUE(lines.ok());
  const size_t n = 20000;
  const std::vector<Point2> exact = ExactPoints(e, n, 7);
  const std::vector<Point2> spread = SpreadBesideLines(exact, 2e-3, 8);
  BoxDiscrepancyOptions o;
  o.sample_corners = 128, o.random_corners = 64, o.background = 64, o.random_boxes = 20000;
  auto d_exact = SampleAnchoredBoxDiscrepancy(*s, *uniform, *lines, exact, o);
  auto d_spread = SampleAnchoredBoxDiscrepancy(*s, *uniform, *lines, spread, o);
  ASSERT_TRUE(d_exact.ok() && d_spread.ok());
  // i.i.d. points: of the order of 1/sqrt(N).
  EXPECT_LT(d_exact->d, 3 / std::sqrt(static_cast<double>(n)));
  // Each line's side loses ~1 % of all points from its first 1e-4 (9.2 %
  // of the mass lies there, 1.25 % after spreading, over 8 sides); a box
  // whose edges cut two such strips sees ~2 %.
  EXPECT_GT(d_spread->d, 0.015);
  EXPECT_GT(d_spread->d, 2 * d_exact->d);
  // The worst box ends within 2e-3 of a longitude line.
  const double v_edge = std::min(std::fabs(d_spread->v0 - std::round(d_spread->v0 * 4) / 4),
                                 std::fabs(d_spread->v1 - std::round(d_spread->v1 * 4) / 4));
  EXPECT_LT(v_edge, 2e-3);
  // A fixed 256 x 256 grid (cells of 3.9e-3) cannot tell the two sets apart.
  auto cells = GradedCellMasses(*s, *uniform, 256, 8);
  ASSERT_TRUE(cells.ok());
  auto cell_mass = [&](double u0, double v0, double) {
    return (*cells)[std::lround(u0 * 256) * 256 + std::lround(v0 * 256)];
  };
  const double grid_exact = ParameterRectDiscrepancy(exact, cell_mass, 256);
  const double grid_spread = ParameterRectDiscrepancy(spread, cell_mass, 256);
  EXPECT_LT(grid_spread, 1.5 * grid_exact) << grid_exact << " " << grid_spread;
}

}  // namespace
}  // namespace sfc
