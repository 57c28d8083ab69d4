// Features at generic positions (docs/ALGORITHM.md, "Features inside a
// leaf"): a density step, a line where the area element blows up and a crease
// where it vanishes, each at an irrational position off every curve's cell
// grid, on the default curve. The exact shares and means are closed forms
// written here from the definitions, sharing nothing with the sampler. Before
// version 4 each of these held an error that did not shrink with N (a step's
// share +3e-4, the blow-up's mean +4e-4, the crease's mean -1.8e-5).
// bench/generic_features.py runs the same checks at the N, from the
// CLI's output.
#include <cmath>
#include <string>

#include "core/leaf_walk.h"
#include "gtest/gtest.h"
#include "tests/test_util.h"

namespace sfc {
namespace {

SampleBatch Samples(const std::string& surface, const std::string& density, uint64_t n,
                    uint64_t seed) {
  const auto setup = testing::MakeSetup(surface, density, n);
  return testing::Collect(testing::MakeSampler(setup, SequenceKind::kJittered, n, seed), 0, n, {},
                          {}, 1 << 16);
}

std::string Number(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.17g", x);
  return text;
}

// The plane with density 1 below the step and 10 above: the share below is
// c / (c + 10 (1 - c)), and the samples within 4e-3 of the step on either
// side are within 5 % of their exact counts.
void ExpectStepHolds(bool along_u, double c, uint64_t n, uint64_t seed) {
  const std::string axis = along_u ? "u" : "v";
  const SampleBatch s = Samples("plane", "expr:" + axis + "<" + Number(c) + " ? 1 : 10", n, seed);
  ASSERT_EQ(s.size(), n);
  const double total = c + 10 * (1 - c);
  double below = 0, just_below = 0, just_above = 0;
  for (size_t i = 0; i < n; ++i) {
    const double t = along_u ? s.u[i] : s.v[i];
    below += t < c;
    just_below += t >= c - 4e-3 && t < c;
    just_above += t >= c && t < c + 4e-3;
  }
  const std::string where = axis + " < " + Number(c) + ", seed " + std::to_string(seed);
  EXPECT_NEAR(below / n, c / total, 5e-5) << where;
  EXPECT_NEAR(just_below, n * 4e-3 / total, 0.05 * n * 4e-3 / total) << where;
  EXPECT_NEAR(just_above, n * 4e-2 / total, 0.05 * n * 4e-2 / total) << where;
}

TEST(GenericFeatures, ADensityStepOffTheGridKeepsItsShareAndItsStrips) {
  for (uint64_t seed : {1, 2, 3}) {
    ExpectStepHolds(true, 1 / std::sqrt(7.0), 1 << 20, seed);
    ExpectStepHolds(false, 1 / std::sqrt(13.0), 1 << 20, seed);
  }
}

TEST(GenericFeatures, ABlowUpLineOffTheGridKeepsItsStripsAndMeans) {
  // x = cbrt(u - c): under the area measure x is uniform on
  // [-cbrt(c), cbrt(1 - c)] and y on [0, 1].
  const double c = 1 / std::sqrt(5.0);
  const std::string surface =
      "expr:x=sign(u-" + Number(c) + ")*abs(u-" + Number(c) + ")^(1/3);y=v;z=0;u0=0;u1=1;v0=0;v1=1";
  const double x0 = -std::cbrt(c), x1 = std::cbrt(1 - c), width = x1 - x0;
  const double exact_mean = (std::exp(x1) - std::exp(x0)) / width + 1.0 / 3;
  const uint64_t n = 1 << 18;
  for (uint64_t seed : {1, 2, 3}) {
    const SampleBatch s = Samples(surface, "uniform", n, seed);
    ASSERT_EQ(s.size(), n);
    double sum = 0;
    double near[2][3] = {};  // side, band: |u - c| in [0, 1e-4), [1e-4, 1e-3), [1e-3, 1e-2)
    for (size_t i = 0; i < n; ++i) {
      sum += std::exp(s.x[i]) + s.y[i] * s.y[i];
      const double d = std::fabs(s.u[i] - c);
      const int side = s.u[i] >= c;
      if (d < 1e-2) ++near[side][d < 1e-4 ? 0 : d < 1e-3 ? 1 : 2];
    }
    EXPECT_NEAR(sum / n, exact_mean, 4e-5) << "seed " << seed;
    const double edges[4] = {0, 1e-4, 1e-3, 1e-2};
    for (int side = 0; side < 2; ++side) {
      for (int b = 0; b < 3; ++b) {
        const double exact = n * (std::cbrt(edges[b + 1]) - std::cbrt(edges[b])) / width;
        EXPECT_NEAR(near[side][b], exact, std::max(0.05 * exact, 3 * std::sqrt(exact)))
            << "seed " << seed << " side " << side << " band " << b;
      }
    }
  }
}

TEST(GenericFeatures, ACreaseWhereTheAreaElementVanishesKeepsItsMean) {
  // The double cone over u in [-0.3, 0.7]: the area element is proportional
  // to |u|, whose integral is (0.3^2 + 0.7^2) / 2 = 0.29, so the mean of
  // z = u is (0.7^3 - 0.3^3) / 3 / 0.29.
  const std::string surface = "expr:x=u*cos(2*_pi*v);y=u*sin(2*_pi*v);z=u;u0=-0.3;u1=0.7;v0=0;v1=1";
  const double exact_mean = (0.343 - 0.027) / 3 / ((0.49 + 0.09) / 2);
  const uint64_t n = 1 << 20;
  for (uint64_t seed : {1, 2, 3}) {
    const SampleBatch s = Samples(surface, "uniform", n, seed);
    ASSERT_EQ(s.size(), n);
    double sum = 0, band = 0;
    for (size_t i = 0; i < n; ++i) {
      sum += s.z[i];
      band += std::fabs(s.z[i]) > 1e-3 && std::fabs(s.z[i]) < 1e-2;
    }
    EXPECT_NEAR(sum / n, exact_mean, 5e-6) << "seed " << seed;
    // Each side holds (1e-2^2 - 1e-3^2) / 2 of the total mass 0.29.
    const double exact_band = 2 * n * (1e-4 - 1e-6) / 0.58;
    EXPECT_NEAR(band, exact_band, std::max(0.05 * exact_band, 3 * std::sqrt(exact_band)))
        << "seed " << seed;
  }
}

TEST(GenericFeatures, ARefinedTreeAcrossAStepEqualsAFreshBuild) {
  const auto surface = MakeSurface("plane");
  const auto density = MakeDensity("expr:u<" + Number(1 / std::sqrt(7.0)) + " ? 1 : 10");
  ASSERT_TRUE(surface.ok() && density.ok());
  const Surface& sf = *surface->surface;
  const Density& df = *density->density;
  const auto coarse = CurveTree::Build(sf, df, {}, 12);
  const auto fresh = CurveTree::Build(sf, df, {}, 20);
  ASSERT_TRUE(coarse.ok() && fresh.ok());
  const auto refined = (*coarse)->Refined(sf, df, 20);
  ASSERT_TRUE(refined.ok());
  ASSERT_GT((*fresh)->leaf_count(), 4 * (*coarse)->leaf_count());  // the step was refined
  ASSERT_EQ((*refined)->leaf_count(), (*fresh)->leaf_count());
  for (size_t l = 0; l < (*fresh)->leaf_count(); ++l) {
    ASSERT_EQ((*refined)->leaf_start(l), (*fresh)->leaf_start(l)) << l;
    ASSERT_EQ((*refined)->mass_end(l), (*fresh)->mass_end(l)) << l;
    ASSERT_EQ((*refined)->leaf_fail_grade(l), (*fresh)->leaf_fail_grade(l)) << l;
  }
}

TEST(GenericFeatures, SamplesInALeafCutByAStepLandOnItsHeavySide) {
  // Density 0 on one side of a line at a generic position, along an axis and
  // oblique: a leaf the line cuts carries a tiny fraction of a sample, and its
  // quadratic spreads the mass over the whole leaf. Its first table follows
  // the true density at the centres of LeafWalk::kExactCells^2 cells, so a
  // sample where the density is 0 lies within one such cell of the line:
  // closer than side / kExactCells * sqrt(2) for its leaf's side.
  const uint64_t n = 1 << 20;
  struct Case {
    std::string line;  // f(u, v) = 0 on the line, density 1 where f >= 0
    double gu, gv;     // the gradient of f (f is linear)
  };
  const double c = 1 / std::sqrt(7.0);
  for (const Case& k : {Case{"u-" + Number(c), 1, 0},
                        Case{"u+" + Number(1 / std::sqrt(11.0)) + "*v-" + Number(0.61803398874989),
                             1, 1 / std::sqrt(11.0)}}) {
    const std::string density = "expr:" + k.line + "<0 ? 0 : 1";
    const auto setup = testing::MakeSetup("plane", density, n);
    const CurveTree& tree = *setup.tree;
    const double offset = k.line == "u-" + Number(c) ? -c : -0.61803398874989;
    const double norm = std::hypot(k.gu, k.gv);
    for (uint64_t seed : {1, 2, 3}) {
      const SampleBatch s = testing::Collect(
          testing::MakeSampler(setup, SequenceKind::kJittered, n, seed), 0, n, {}, {}, 1 << 16);
      ASSERT_EQ(s.size(), n);
      int wrong_side = 0;
      for (size_t i = 0; i < n; ++i) {
        const double f = k.gu * s.u[i] + k.gv * s.v[i] + offset;
        if (f >= 0) continue;
        ++wrong_side;
        // The leaf holding the sample: the smallest cell that contains it.
        double side = 1;
        for (size_t l = 0; l < tree.leaf_count(); ++l) {
          const CurveTree::Cell cell = tree.LeafCell(l);
          if (s.u[i] >= cell.u0 && s.u[i] <= cell.u0 + cell.size && s.v[i] >= cell.v0 &&
              s.v[i] <= cell.v0 + cell.size) {
            side = std::min(side, cell.size);
          }
        }
        EXPECT_LT(-f / norm, side / LeafWalk::kExactCells * std::sqrt(2.0))
            << density << ", seed " << seed << ", sample " << s.index[i];
      }
      EXPECT_LE(wrong_side, 3) << density << ", seed " << seed;
    }
  }
}

}  // namespace
}  // namespace sfc
