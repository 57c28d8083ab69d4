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

// A density that is a power of the distance to one edge, t^p, is constant
// in the coordinates warped by k = 1 / (1 + p): the warped model then shares
// mass exactly as the density does, over any sub-rectangle, whichever edge
// is singular and whether the density blows up (p < 0) or vanishes (p > 0).
TEST(LeafModel, WarpedModelFollowsAPowerLawTowardAnEdge) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> pos(0, 1);
  for (double p : {-2.0 / 3, -0.75, -1.0 / 3, 1.0, 3.0}) {
    for (int side = 0; side < 2; ++side) {
      for (int axis = 0; axis < 2; ++axis) {
        const float k = static_cast<float>((side == 0 ? 1 : -1) / (1 + p));
        float warp[2] = {1, 1};
        warp[axis] = k;
        // The distance-to-edge CDF along the warped axis: the mass of [0, x].
        auto cdf = [&](double x) {
          return side == 0 ? std::pow(x, 1 + p) : 1 - std::pow(1 - x, 1 + p);
        };
        double values[9];
        for (int i = 0; i < 3; ++i) {
          for (int j = 0; j < 3; ++j) {
            const double s = kGaussNode[axis == 0 ? i : j];
            const double x = Warp(k, s);
            const double t = side == 0 ? x : 1 - x;
            values[3 * i + j] = (1 + p) * std::pow(t, p) * WarpSlope(k, s);
          }
        }
        const LeafModel m = LeafModel::FromQuadratic(values, warp);
        for (int trial = 0; trial < 20; ++trial) {
          double a0 = pos(rng), a1 = pos(rng), b0 = pos(rng), b1 = pos(rng);
          if (a0 > a1) std::swap(a0, a1);
          if (b0 > b1) std::swap(b0, b1);
          const double exact = (cdf(a1) - cdf(a0)) * (b1 - b0);
          const double got = axis == 0
                                 ? ModelIntegral(m, LeafModel::Kind::kQuadratic, 2, a0, a1, b0, b1)
                                 : ModelIntegral(m, LeafModel::Kind::kQuadratic, 2, b0, b1, a0, a1);
          EXPECT_NEAR(got, exact, 2e-6) << "p " << p << " side " << side << " axis " << axis;
        }
        // The sub-squares of a square touching the singular edge share its
        // integral as the density does.
        for (int grid : {2, 3}) {
          const double side_len = 1.0 / 64, x0 = side == 0 ? 0 : 1 - side_len, y0 = 0.5;
          double out[9];
          SubSquareIntegrals(m, LeafModel::Kind::kQuadratic, grid, axis == 0 ? x0 : y0,
                             axis == 0 ? y0 : x0, side_len, out);
          const double step = side_len / grid;
          for (int i = 0; i < grid; ++i) {
            for (int j = 0; j < grid; ++j) {
              const int along = axis == 0 ? i : j, across = axis == 0 ? j : i;
              const double lo = x0 + along * step;
              const double exact = (cdf(lo + step) - cdf(lo)) * step;
              (void)across;
              EXPECT_NEAR(out[i * grid + j] / exact, 1.0, 2e-5)
                  << "p " << p << " side " << side << " axis " << axis << " grid " << grid;
            }
          }
        }
      }
    }
  }
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
