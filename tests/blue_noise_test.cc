// Blue-noise figures and their reference sets (evaluation/blue_noise.h).
#include "evaluation/blue_noise.h"

#include <cmath>

#include "evaluation/reference_sets.h"
#include "gtest/gtest.h"

namespace sfc {
namespace {

TEST(BlueNoise, HexagonalLatticeScoresOne) {
  // A hexagonal lattice of spacing d fills the square with ~2 / (sqrt 3 d^2)
  // points; its nearest neighbours are all at d.
  const double d = 0.02;
  std::vector<Point2> pts;
  for (int row = 0; row * d * std::sqrt(3.0) / 2 < 1; ++row) {
    for (double x = (row % 2) * d / 2; x < 1; x += d)
      pts.push_back({x, row * d * std::sqrt(3.0) / 2});
  }
  const NearestNeighbour nn = PlaneNearestNeighbour(pts);
  // The spacing for this many points differs from d only by the lattice's
  // boundary rows and columns.
  EXPECT_NEAR(nn.min, nn.mean, 1e-9);
  EXPECT_NEAR(nn.min, 1, 0.03);
}

TEST(BlueNoise, DartThrowingKeepsItsRadius) {
  const std::vector<Point2> p = DartThrowingSquare(2000, 0.7, 3);
  ASSERT_EQ(p.size(), 2000u);
  EXPECT_GE(PlaneNearestNeighbour(p).min, 0.7);
  const std::vector<Vec3> s = DartThrowingSphere(2000, 0.7, 3);
  ASSERT_EQ(s.size(), 2000u);
  EXPECT_GE(SphereNearestNeighbour(s).min, 0.7);
  // Jittered points come much closer.
  EXPECT_LT(PlaneNearestNeighbour(JitteredSquare(2000, 3)).min, 0.4);
}

TEST(BlueNoise, PowerSpectrumOfALatticeAndOfWhiteNoise) {
  // A 32 x 32 lattice: every wave vector off 32 Z^2 cancels, so P(f) = 0
  // below f = 32 and P(32) > 0.
  std::vector<Point2> lattice;
  for (int i = 0; i < 32; ++i) {
    for (int j = 0; j < 32; ++j) lattice.push_back({(i + 0.5) / 32, (j + 0.5) / 32});
  }
  const std::vector<double> p = RadialPowerSpectrum(lattice, 40);
  for (int f = 1; f < 32; ++f) ASSERT_LT(p[f - 1], 1e-9) << f;
  EXPECT_GT(p[31], 10);
  // Independent uniform points: P = 1 on average at every f.
  std::vector<Point2> white;
  uint64_t state = 12345;
  auto next = [&] {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return static_cast<double>(state >> 11) * 0x1.0p-53;
  };
  for (int i = 0; i < 2000; ++i) white.push_back({next(), next()});
  const std::vector<double> w = RadialPowerSpectrum(white, 40);
  double mean = 0;
  for (int f = 10; f <= 40; ++f) mean += w[f - 1] / 31;
  EXPECT_NEAR(mean, 1, 0.1);
}

TEST(BlueNoise, ScrambledSobolIsStillANet) {
  // Owen scrambling keeps the (0, m, 2)-net property: every elementary box
  // of area 2^-m holds exactly one of the first 2^m points.
  const int m = 8;
  for (uint64_t seed : {1, 2}) {
    const std::vector<Point2> p = ScrambledSobolSquare(1 << m, seed);
    for (int i = 0; i <= m; ++i) {
      std::vector<int> count(1 << m, 0);
      for (const Point2& q : p) {
        const int a = static_cast<int>(q.x * (1 << i)), b = static_cast<int>(q.y * (1 << (m - i)));
        ++count[(a << (m - i)) + b];
      }
      for (int c : count) ASSERT_EQ(c, 1) << "seed " << seed << ", " << i << " x-bits";
    }
    // And it is not the unscrambled set.
    EXPECT_NE(p[1].x, SobolSquare(2)[1].x);
  }
}

}  // namespace
}  // namespace sfc
