// The leaf model: its integrals are exact on polynomials of its degree, over
// the cell and over any sub-rectangle; the piecewise kind shares mass by
// sub-square.
#include "core/leaf_model.h"

#include <cmath>
#include <random>

#include "gtest/gtest.h"

namespace sfc {
namespace {

// A random polynomial of degree <= 2 in x and <= 2 in y, with its exact
// integral over a rectangle.
struct Poly {
  double a[3][3];
  double operator()(double x, double y) const {
    double s = 0;
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) s += a[i][j] * std::pow(x, i) * std::pow(y, j);
    }
    return s;
  }
  double Integral(double x0, double x1, double y0, double y1) const {
    double s = 0;
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) {
        s += a[i][j] * (std::pow(x1, i + 1) - std::pow(x0, i + 1)) / (i + 1) *
             (std::pow(y1, j + 1) - std::pow(y0, j + 1)) / (j + 1);
      }
    }
    return s;
  }
};

TEST(LeafModel, QuadraticIntegralsAreExactOnBiquadratics) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> coef(-1, 1), pos(0, 1);
  for (int trial = 0; trial < 50; ++trial) {
    Poly p;
    for (auto& row : p.a) {
      for (double& c : row) c = coef(rng);
    }
    double values[9];
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) values[3 * i + j] = p(kGaussNode[i], kGaussNode[j]);
    }
    EXPECT_NEAR(QuadraticIntegral(values, 0, 1, 0, 1), p.Integral(0, 1, 0, 1), 1e-14);
    for (int r = 0; r < 20; ++r) {
      double x0 = pos(rng), x1 = pos(rng), y0 = pos(rng), y1 = pos(rng);
      if (x0 > x1) std::swap(x0, x1);
      if (y0 > y1) std::swap(y0, y1);
      EXPECT_NEAR(QuadraticIntegral(values, x0, x1, y0, y1), p.Integral(x0, x1, y0, y1), 1e-14);
    }
    // Tiny sub-squares, as deep in a descent: no cancellation. There the
    // integral is h^2 times the value at the centre, up to O(h^4).
    const double h = 1e-9, x = pos(rng) * (1 - h), y = pos(rng) * (1 - h);
    const double dx = (x + h) - x, dy = (y + h) - y;  // the rectangle actually represented
    const double centre = dx * dy * p(x + dx / 2, y + dy / 2);
    EXPECT_NEAR(QuadraticIntegral(values, x, x + h, y, y + h), centre, 1e-12 * h * h);
  }
}

TEST(LeafModel, NormalisedModelIntegratesToOneAndKeepsShares) {
  double values[9];
  for (int k = 0; k < 9; ++k) values[k] = 1 + k;
  const LeafModel m = LeafModel::FromQuadratic(values);
  EXPECT_NEAR(ModelIntegral(m, LeafModel::Kind::kQuadratic, 2, 0, 1, 0, 1), 1.0, 1e-6);
  const double total = QuadraticIntegral(values, 0, 1, 0, 1);
  EXPECT_NEAR(ModelIntegral(m, LeafModel::Kind::kQuadratic, 2, 0, 0.5, 0.25, 0.75),
              QuadraticIntegral(values, 0, 0.5, 0.25, 0.75) / total, 1e-6);
}

TEST(LeafModel, PiecewiseModelSharesMassBySubSquare) {
  for (int grid : {2, 3}) {
    double masses[9] = {};
    for (int k = 0; k < grid * grid; ++k) masses[k] = k + 1;
    double total = 0;
    for (int k = 0; k < grid * grid; ++k) total += masses[k];
    const LeafModel m = LeafModel::FromPiecewise(masses, grid);
    const double side = 1.0 / grid;
    for (int i = 0; i < grid; ++i) {
      for (int j = 0; j < grid; ++j) {
        EXPECT_NEAR(ModelIntegral(m, LeafModel::Kind::kPiecewise, grid, i * side, (i + 1) * side,
                                  j * side, (j + 1) * side),
                    masses[i * grid + j] / total, 1e-6);
        // Half of a sub-square holds half its mass.
        EXPECT_NEAR(ModelIntegral(m, LeafModel::Kind::kPiecewise, grid, i * side, (i + 0.5) * side,
                                  j * side, (j + 1) * side),
                    masses[i * grid + j] / total / 2, 1e-6);
      }
    }
  }
}

TEST(LeafModel, InvalidValuesGiveTheUniformModel) {
  double values[9] = {1, 1, 1, 1, NAN, 1, 1, 1, 1};
  const LeafModel m = LeafModel::FromQuadratic(values);
  EXPECT_NEAR(ModelIntegral(m, LeafModel::Kind::kQuadratic, 2, 0, 0.5, 0, 0.5), 0.25, 1e-6);
}

}  // namespace
}  // namespace sfc
