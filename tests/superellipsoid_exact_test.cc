// The closed-form superellipsoid quadrature (evaluation/superellipsoid_exact.h)
// against exact values, and against the graded box measure, which reaches
// the same numbers by another route (the Surface's jets, graded cells).
#include "evaluation/superellipsoid_exact.h"

#include <cmath>

#include "core/builtin_surfaces.h"
#include "evaluation/box_discrepancy.h"
#include "gtest/gtest.h"

namespace sfc {
namespace {

constexpr double kPi = 3.14159265358979323846;

TEST(SuperellipsoidExact, SphereAndOctahedron) {
  EXPECT_NEAR(SuperellipsoidArea(1), 4 * kPi, 1e-12);
  // e = 2: the octahedron |x| + |y| + |z| = 1, area 4 sqrt 3.
  EXPECT_NEAR(SuperellipsoidArea(2), 4 * std::sqrt(3.0), 1e-12);
  // The unit sphere's strips: |a| < pi d has fraction sin(pi d).
  EXPECT_NEAR(SuperellipsoidEquatorStripFraction(1, 0.01), std::sin(kPi * 0.01), 1e-14);
  EXPECT_NEAR(SuperellipsoidLongitudeStripFraction(1, 0.01), 8 * 0.01, 1e-14);
  EXPECT_NEAR(SuperellipsoidPoleStripFraction(1, 0.01), 1 - std::cos(kPi * 0.01), 1e-14);
  EXPECT_NEAR(SuperellipsoidMeanX2(1), 1.0 / 3, 1e-14);
}

TEST(SuperellipsoidExact, ConvergedOnTheSingularCases) {
  // Each value is a 2D rule; halving the strip must change the fraction like
  // d^e near a |t|^(e-1) line (the leading term), a check that the grading
  // resolves the singularity rather than a copied number.
  for (double e : {1.0 / 3, 0.25}) {
    const double f1 = SuperellipsoidLongitudeStripFraction(e, 1e-6);
    const double f2 = SuperellipsoidLongitudeStripFraction(e, 2e-6);
    EXPECT_NEAR(std::log(f2 / f1) / std::log(2.0), e, 1e-3) << e;
  }
  // Area of x^6 + y^6 + z^6 = 1 between the inscribed sphere's and the cube's.
  const double a = SuperellipsoidArea(1.0 / 3);
  EXPECT_GT(a, 4 * kPi);
  EXPECT_LT(a, 24);
}

TEST(SuperellipsoidExact, AnglesFromPoints) {
  auto s = MakeSuperellipsoid(1.0 / 3, false);
  for (double u : {0.1, 0.3, 0.49999, 0.7}) {
    for (double v : {0.01, 0.26, 0.5001, 0.9}) {
      const Vec3 p = s->Point(u, v);
      EXPECT_NEAR(SuperellipsoidLongitude(1.0 / 3, p.x, p.y), -kPi + 2 * kPi * v, 1e-12);
      EXPECT_NEAR(SuperellipsoidLatitude(1.0 / 3, p.x, p.y, p.z), -kPi / 2 + kPi * u, 1e-12);
    }
  }
}

// Two routes to the same numbers: closed form in the angles, and the graded
// box measure on the Surface's jets.
TEST(SuperellipsoidExact, AgreesWithTheGradedBoxMeasure) {
  auto uniform = MakeUniformDensity();
  for (double e : {1.0 / 3, 0.25, 2.0, 3.0}) {
    auto s = MakeSuperellipsoid(e, false);
    auto lines = DetectSingularLines(*s, *uniform);
    ASSERT_TRUE(lines.ok());
    // Exactly the known lines: latitude 0, 1/2, 1; longitude 0, 1/4 .. 1.
    EXPECT_EQ(lines->u, (std::vector<double>{0, 0.5, 1})) << e;
    EXPECT_EQ(lines->v, (std::vector<double>{0, 0.25, 0.5, 0.75, 1})) << e;
    // Strips beside the four longitude lines (unit v) and the equator (u = 1/2).
    std::vector<double> vb, ub;
    for (double d : {1e-4, 1e-3, 1e-2}) {
      for (double l : {0.0, 0.25, 0.5, 0.75, 1.0}) vb.push_back(l - d), vb.push_back(l + d);
      ub.push_back(0.5 - d), ub.push_back(0.5 + d);
    }
    auto m = GradedBoxMeasure::Build(*s, *uniform, *lines, ub, vb);
    ASSERT_TRUE(m.ok()) << m.status().message();
    const double total = m->total();
    EXPECT_NEAR(total, SuperellipsoidArea(e), 1e-7 * total) << e;
    const size_t nu = m->u().size() - 1, nv = m->v().size() - 1;
    for (double d : {1e-4, 1e-3, 1e-2}) {
      double strip = m->Mass(0, nu, 0, m->VIndex(d)) + m->Mass(0, nu, m->VIndex(1 - d), nv);
      for (double l : {0.25, 0.5, 0.75})
        strip += m->Mass(0, nu, m->VIndex(l - d), m->VIndex(l + d));
      EXPECT_NEAR(strip / total, SuperellipsoidLongitudeStripFraction(e, d), 2e-8) << e << " " << d;
      const double eq = m->Mass(m->UIndex(0.5 - d), m->UIndex(0.5 + d), 0, nv);
      EXPECT_NEAR(eq / total, SuperellipsoidEquatorStripFraction(e, d), 2e-8) << e << " " << d;
    }
  }
}

}  // namespace
}  // namespace sfc
