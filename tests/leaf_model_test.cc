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

// A density that is a power of the distance to a line, |x - c|^p, is
// constant in the coordinates warped by k = 1 / (1 + p) (AxisWarp): the
// warped model then shares mass exactly as the density does, over any
// sub-rectangle, whether the line is an edge (c = 0, 1) or crosses the cell,
// and whether the density blows up (p < 0) or vanishes (p > 0).
TEST(LeafModel, WarpedModelFollowsAPowerLawAboutALine) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> pos(0, 1);
  for (double p : {-2.0 / 3, -0.75, -1.0 / 3, 1.0, 3.0}) {
    for (double c : {0.0, 1.0, 0.25, 0.5}) {
      for (int axis = 0; axis < 2; ++axis) {
        const AxisWarp w = {static_cast<float>(1 / (1 + p)), static_cast<float>(c)};
        AxisWarp warp[2] = {kNoWarp, kNoWarp};
        warp[axis] = w;
        // The normalised mass of [0, x] along the warped axis.
        const double z = std::pow(c, 1 + p) + std::pow(1 - c, 1 + p);
        auto cdf = [&](double x) {
          return (x < c ? std::pow(c, 1 + p) - std::pow(c - x, 1 + p)
                        : std::pow(c, 1 + p) + std::pow(x - c, 1 + p)) /
                 z;
        };
        double values[9];
        for (int i = 0; i < 3; ++i) {
          for (int j = 0; j < 3; ++j) {
            const double s = WarpNode(w, kGaussNode[axis == 0 ? i : j]);
            values[3 * i + j] = std::pow(std::fabs(Warp(w, s) - c), p) * WarpSlope(w, s);
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
          EXPECT_NEAR(got, exact, 2e-6) << "p " << p << " c " << c << " axis " << axis;
        }
        // The sub-squares of a small square beside the line, in the
        // coordinates the walk descends in (DescendsWarped), share its
        // integral as the density does over them.
        const bool warped = DescendsWarped(w);
        auto leaf = [&](double x) { return warped ? Warp(w, x) : x; };
        for (int grid : {2, 3}) {
          const double side = 1.0 / 64, y0 = 0.5;
          const double x0 = c == 1 ? 1 - side : warped ? WarpSplit(w) : c;
          GridFactors factors;
          ComputeGridFactors(m, LeafModel::Kind::kQuadratic, grid, axis == 0 ? x0 : y0,
                             axis == 0 ? y0 : x0, side, grid, &factors);
          const double step = side / grid;
          for (int i = 0; i < grid; ++i) {
            for (int j = 0; j < grid; ++j) {
              const double lo = x0 + (axis == 0 ? i : j) * step;
              const double exact = (cdf(leaf(lo + step)) - cdf(leaf(lo))) * step;
              EXPECT_NEAR(factors.Integral(i, j) / exact, 1.0, 2e-5)
                  << "p " << p << " c " << c << " axis " << axis << " grid " << grid;
            }
          }
        }
      }
    }
  }
}

// The warp is a bijection of [0, 1] onto itself with the slope as its
// derivative, its inverse exact to rounding, and its two pieces meet at the
// line.
TEST(LeafModel, AxisWarpIsAMonotoneBijection) {
  for (float k : {3.0f, 1.5f, 0.5f, 0.25f}) {
    for (float c : {0.0f, 1.0f, 0.25f, 0.5f, 0.7f}) {
      const AxisWarp w = {k, c};
      EXPECT_EQ(Warp(w, 0), 0);
      EXPECT_EQ(Warp(w, 1), 1);
      EXPECT_NEAR(Warp(w, WarpSplit(w)), c, 1e-15);
      double last = 0;
      for (int i = 1; i < 1000; ++i) {
        const double s = i / 1000.0, x = Warp(w, s);
        EXPECT_GT(x, last);
        last = x;
        // x carries 1e-16 absolute: near the line, Unwarp's root magnifies it.
        EXPECT_NEAR(Unwarp(w, x), s, 1e-9) << k << " " << c;
        const double d = 1e-7;
        if (std::fabs(s - WarpSplit(w)) < 1e-3) continue;  // W' has a root or a pole there
        EXPECT_NEAR((Warp(w, s + d) - Warp(w, s - d)) / (2 * d), WarpSlope(w, s),
                    1e-4 * (1 + WarpSlope(w, s)))
            << k << " " << c << " " << s;
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
