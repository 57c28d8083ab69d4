// The exact means of issue 36's integration table (evaluation/integration.h).
#include "evaluation/integration.h"

#include <cmath>

#include "gtest/gtest.h"

namespace sfc {
namespace {

// e = 1 makes the superellipsoid the unit sphere: its quadrature (after the
// substitution for the singular lines of e != 1) meets the closed form.
TEST(Integration, SuperellipsoidOfExponentOneIsTheSphere) {
  EXPECT_NEAR(SuperellipsoidMeanOfF(1.0), SphereMeanOfF(), 1e-13);
}

// A torus with R >> r is nearly a cylinder of radius r about a circle of
// radius R: the mean of x^2 tends to R^2 / 2, and of exp(z) to I0(r), the
// mean of exp(r sin b) over b. Here the exact torus mean against R^2 / 2 +
// I0(r) + O(r^2) terms: the difference is the x^2 cross terms, r^2 / 4 + ...
TEST(Integration, TorusMeanIsThatOfAThinTube) {
  const double r = 1e-3, big_r = 1;
  // The mean of x^2 = (R + r cos b)^2 cos^2 a weighted by R + r cos b:
  // (R^2 + 3 r^2 / 2) / 2 exactly; exp(z) = exp(r sin b), weight R + r cos b:
  // I0(r) = 1 + r^2 / 4 + ...; y z averages to 0.
  const double expected = (big_r * big_r + 1.5 * r * r) / 2 + 1 + r * r / 4;
  EXPECT_NEAR(TorusMeanOfF(big_r, r), expected, 1e-12);
}

}  // namespace
}  // namespace sfc
