// The evaluation's reference measure is checked against exact areas: the
// unit sphere (the superellipsoid with exponent 1) and the torus, and on the
// singular superellipsoid two parameterisations of one surface agree.
#include "evaluation/reference_measure.h"

#include <cmath>
#include <numeric>

#include "core/builtin_surfaces.h"
#include "gtest/gtest.h"

namespace sfc {
namespace {

constexpr double kPi = 3.14159265358979323846;

double Total(const Surface& s, int grid, int nodes) {
  auto uniform = MakeUniformDensity();
  auto m = GradedCellMasses(s, *uniform, grid, nodes);
  EXPECT_TRUE(m.ok()) << m.status().message();
  return m.ok() ? std::accumulate(m->begin(), m->end(), 0.0) : 0;
}

TEST(ReferenceMeasure, ExactAreas) {
  EXPECT_NEAR(Total(*MakeSuperellipsoid(1, false), 64, 8), 4 * kPi, 1e-10);
  EXPECT_NEAR(Total(*MakeSphere(1), 64, 8), 4 * kPi, 1e-10);
  EXPECT_NEAR(Total(*MakeTorus(1, 0.25), 32, 8), 4 * kPi * kPi * 0.25, 1e-10);
}

TEST(ReferenceMeasure, ConvergesOnTheSingularSuperellipsoid) {
  // Area of x^6 + y^6 + z^6 = 1 by two parameterisations and two rules.
  const double plain = Total(*MakeSuperellipsoid(1.0 / 3, false), 64, 8);
  const double plain_fine = Total(*MakeSuperellipsoid(1.0 / 3, false), 128, 12);
  const double reparam = Total(*MakeSuperellipsoid(1.0 / 3, true), 128, 12);
  EXPECT_NEAR(plain, plain_fine, 1e-6 * plain);
  EXPECT_NEAR(plain_fine, reparam, 1e-6 * plain);
  // Between the inscribed sphere's area and the circumscribed cube's.
  EXPECT_GT(plain, 4 * kPi);
  EXPECT_LT(plain, 24);
}

}  // namespace
}  // namespace sfc
