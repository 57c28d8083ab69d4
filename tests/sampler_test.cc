// Properties of equalisation and the sample sets: determinism, random access
// (ranges, shards, regions equal slices and filters of the full set),
// samples on the surface, and counts per cell within the jittering bound.
#include "core/sampler.h"

#include <cmath>
#include <set>
#include <vector>

#include "gtest/gtest.h"
#include "tests/test_util.h"

namespace sfc {
namespace {

using testing::Collect;
using testing::MakeSampler;
using testing::MakeSetup;

void ExpectSameSamples(const SampleBatch& a, const SampleBatch& b) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a.index[i], b.index[i]) << i;
    ASSERT_EQ(a.u[i], b.u[i]) << i;  // bit-identical, not approximately
    ASSERT_EQ(a.v[i], b.v[i]) << i;
    ASSERT_EQ(a.x[i], b.x[i]) << i;
    ASSERT_EQ(a.y[i], b.y[i]) << i;
    ASSERT_EQ(a.z[i], b.z[i]) << i;
  }
}

TEST(Sampler, SameRequestAndSeedGiveTheSameSamplesAndOtherSeedsDoNot) {
  const uint64_t n = 3000;
  const auto s1 = MakeSetup("eight", "gaussian:floor=0.1", n);
  const auto s2 = MakeSetup("eight", "gaussian:floor=0.1", n);  // a second, independent build
  const SampleBatch a = Collect(MakeSampler(s1, SequenceKind::kJittered, n, 7), 0, n);
  const SampleBatch b = Collect(MakeSampler(s2, SequenceKind::kJittered, n, 7), 0, n, {}, {}, 17);
  ExpectSameSamples(a, b);
  const SampleBatch c = Collect(MakeSampler(s1, SequenceKind::kJittered, n, 8), 0, n);
  int same = 0;
  for (size_t i = 0; i < n; ++i) same += a.u[i] == c.u[i];
  EXPECT_LT(same, 3);
}

TEST(Sampler, IndexRangesAndShardsAreSlicesOfTheFullSet) {
  const uint64_t n = 5000;
  const auto s = MakeSetup("torus", "uniform", n);
  for (SequenceKind kind : {SequenceKind::kJittered, SequenceKind::kProgressive}) {
    auto sampler = MakeSampler(s, kind, n, 3);
    const SampleBatch full = Collect(sampler, 0, n);
    ASSERT_EQ(full.size(), n);
    // Every index exactly once.
    std::set<uint64_t> indices(full.index.begin(), full.index.end());
    EXPECT_EQ(indices.size(), n);
    if (kind == SequenceKind::kJittered) {
      // Index order is curve order: the range is the slice.
      const SampleBatch part = Collect(sampler, 1234, 3456);
      SampleBatch slice;
      slice.AppendFrom(full, 1234, 3456);
      ExpectSameSamples(part, slice);
      // Shards 0..K-1 concatenated are the full set, in order.
      SampleBatch joined;
      const uint64_t k = 7;
      for (uint64_t i = 0; i < k; ++i) {
        joined.Append(Collect(sampler, i * n / k, (i + 1) * n / k));
      }
      ExpectSameSamples(joined, full);
    }
  }
}

// The set restricted to a region, computed by descending the tree, equals the
// full set filtered by the region, element for element.
TEST(Sampler, RegionQueriesEqualTheFilteredFullSet) {
  const uint64_t n = 20000;
  const auto s = MakeSetup("monkey_saddle", "gaussian:floor=0.05", n);
  auto sampler = MakeSampler(s, SequenceKind::kJittered, n, 11);
  const SampleBatch full = Collect(sampler, 0, n);
  const Region regions[] = {
      Region::ParameterRect(0.1, 0.35, 0.6, 0.95),
      Region::ParameterRect(0.0, 1.0, 0.0, 0.5),
      Region::Box({-0.3, -0.5, -0.2}, {0.4, 0.2, 0.3}),
      Region::Box({0.5, 0.5, -3}, {1, 1, 3}),
  };
  for (const Region& region : regions) {
    SampleBatch expected;
    for (size_t i = 0; i < full.size(); ++i) {
      if (region.Contains(full.u[i], full.v[i], {full.x[i], full.y[i], full.z[i]})) {
        expected.AppendFrom(full, i, i + 1);
      }
    }
    ASSERT_GT(expected.size(), 100u);
    ExpectSameSamples(Collect(sampler, 0, n, region), expected);
  }
}

TEST(Sampler, ThreadedBatchesHoldTheSameSamplesInTheSameOrder) {
  const uint64_t n = 100000;
  const auto s = MakeSetup("eight", "gaussian:floor=0.1", n);
  auto sampler = MakeSampler(s, SequenceKind::kJittered, n, 6);
  SampleFields fields;
  fields.normal = fields.density = fields.curve_position = true;
  const SampleBatch one = Collect(sampler, 17, n - 5, {}, fields, 20000);
  for (int threads : {2, 3}) {
    SampleBatch many;
    auto cursor = *SampleCursor::Create(sampler, 17, n - 5, {}, fields, threads);
    while (*cursor->Next(20000, &many) > 0) {
    }
    ExpectSameSamples(many, one);
    EXPECT_EQ(many.nx, one.nx);
    EXPECT_EQ(many.density, one.density);
    EXPECT_EQ(many.curve_position, one.curve_position);
  }
}

TEST(Sampler, SamplesLieOnTheSurfaceInsideTheParameterBox) {
  const uint64_t n = 4000;
  for (const char* surface : {"sphere:r=2", "whitney", "superellipsoid:reparam=1", "eight"}) {
    const auto s = MakeSetup(surface, "uniform", n);
    const SampleBatch b = Collect(MakeSampler(s, SequenceKind::kJittered, n, 5), 0, n);
    ASSERT_EQ(b.size(), n);
    for (size_t i = 0; i < n; ++i) {
      ASSERT_GE(b.u[i], 0.0);
      ASSERT_LE(b.u[i], 1.0);
      ASSERT_GE(b.v[i], 0.0);
      ASSERT_LE(b.v[i], 1.0);
      const Vec3 p = s.surface->Point(b.u[i], b.v[i]);
      ASSERT_EQ(p, (Vec3{b.x[i], b.y[i], b.z[i]})) << surface << " sample " << i;
    }
  }
  // On the sphere of radius 2 every point is at distance 2 from the centre.
  const auto s = MakeSetup("sphere:r=2", "uniform", n);
  const SampleBatch b = Collect(MakeSampler(s, SequenceKind::kJittered, n, 5), 0, n);
  for (size_t i = 0; i < n; ++i) ASSERT_NEAR(std::hypot(b.x[i], b.y[i], b.z[i]), 2.0, 1e-12);
}

// Samples that land exactly on a singular line of the parameterisation (the
// superellipsoid's |cos|^e where cos = 0: e = 0.1 rounds a band around the
// equator onto u = 1/2) report the surface's normal and curvature density
// there, finite. The normal is checked against the implicit surface's
// |x|^(2/e) + |y|^(2/e) + |z|^(2/e) = 1 gradient, an independent closed form.
TEST(Sampler, NormalsAndCurvatureDensityAreFiniteOnSingularLines) {
  const uint64_t n = 20000;
  const double e = 0.1;
  const auto s = MakeSetup("superellipsoid:e=0.1", "mean:floor=0.05", n);
  SampleFields fields;
  fields.normal = fields.density = true;
  const SampleBatch b = Collect(MakeSampler(s, SequenceKind::kJittered, n, 3), 0, n, {}, fields);
  ASSERT_EQ(b.size(), n);
  size_t on_equator = 0;
  for (size_t i = 0; i < n; ++i) {
    on_equator += b.z[i] == 0;
    ASSERT_TRUE(std::isfinite(b.density[i]) && b.density[i] > 0) << "sample " << i;
    const Vec3 normal{b.nx[i], b.ny[i], b.nz[i]};
    ASSERT_TRUE(IsFinite(normal)) << "sample " << i << " at (u,v) " << b.u[i] << " " << b.v[i];
    ASSERT_NEAR(Norm(normal), 1.0, 1e-12) << "sample " << i;
    auto g = [&](double c) { return std::copysign(std::pow(std::fabs(c), 2 / e - 1), c); };
    Vec3 implicit{g(b.x[i]), g(b.y[i]), g(b.z[i])};
    implicit = implicit * (1 / Norm(implicit));
    // fu x fv points inwards on this parameterisation: -1 everywhere.
    ASSERT_LT(Dot(normal, implicit), -0.99) << "sample " << i << " at (u,v) " << b.u[i] << " "
                                            << b.v[i];
  }
  EXPECT_GT(on_equator, 0u) << "no sample on the singular line: the test checks nothing there";
}

TEST(Sampler, NoTwoSamplesCoincide) {
  // The paper snaps to cell centres; the analytic continuation does not.
  const uint64_t n = 50000;
  CurveTreeOptions coarse;
  coarse.rho = 64;  // leaves hold many samples each
  const auto s = MakeSetup("plane", "expr:u+v", n, coarse);
  const SampleBatch b = Collect(MakeSampler(s, SequenceKind::kJittered, n, 2), 0, n);
  std::set<std::pair<double, double>> points;
  for (size_t i = 0; i < n; ++i) points.insert({b.u[i], b.v[i]});
  EXPECT_EQ(points.size(), n);
  EXPECT_LT(s.tree->leaf_count(), n / 8);
}

// Every cell of the curve's own subdivision is a contiguous stretch of the
// curve, so jittered sampling puts N * mass(cell) / total samples in it, give
// or take the two strata cut by the stretch's ends: |count - expected| < 2,
// plus the error of the area x density estimate.
void ExpectCellCountsWithinJitterBound(
    const char* surface, const char* density, uint64_t n,
    const std::function<double(double, double, double, double)>& true_mass, double total, int depth,
    double slack, const CurveTreeOptions& options = {}) {
  const auto s = MakeSetup(surface, density, n, options);
  const SampleBatch b = Collect(MakeSampler(s, SequenceKind::kJittered, n, 9), 0, n);
  const int side = 1 << depth;
  std::vector<int> counts(side * side, 0);
  for (size_t i = 0; i < n; ++i) {
    const int cx = std::min(side - 1, static_cast<int>(b.u[i] * side));
    const int cy = std::min(side - 1, static_cast<int>(b.v[i] * side));
    ++counts[cx * side + cy];
  }
  double worst = 0;
  for (int cx = 0; cx < side; ++cx) {
    for (int cy = 0; cy < side; ++cy) {
      const double h = 1.0 / side;
      const double expected = n * true_mass(cx * h, (cx + 1) * h, cy * h, (cy + 1) * h) / total;
      worst = std::max(worst, std::fabs(counts[cx * side + cy] - expected));
    }
  }
  EXPECT_LT(worst, 2.0 + slack) << surface << " " << density;
}

TEST(Sampler, CountsPerCellMatchTheAreaOnTheSphere) {
  // Area of the sphere over theta in [pi a, pi b], phi in [2 pi c, 2 pi d].
  const double pi = 3.14159265358979323846;
  auto area = [&](double a, double b, double c, double d) {
    return (std::cos(pi * a) - std::cos(pi * b)) * 2 * pi * (d - c);
  };
  ExpectCellCountsWithinJitterBound("sphere", "uniform", 30000, area, 4 * pi, 3, 0.1);
}

TEST(Sampler, PlacementInsideOneLeafFollowsASteepDensity) {
  // A tolerance no cell fails and a density the quadratic model holds
  // exactly: the whole square is one leaf, and its 10^6 samples must still
  // fill the 16 x 16 sub-cells in proportion to a density that varies
  // 10^4-fold in u and 11-fold in v.
  CurveTreeOptions one_leaf;
  one_leaf.tolerance = 10;
  const auto check = MakeSetup("plane", "expr:(u+0.01)*(u+0.01)*(v+0.1)", 1000000, one_leaf);
  ASSERT_EQ(check.tree->leaf_count(), 1u);
  auto mass = [](double a, double b, double c, double d) {
    auto pu = [](double u) { return (u + 0.01) * (u + 0.01) * (u + 0.01) / 3; };
    auto pv = [](double v) { return (v + 0.1) * (v + 0.1) / 2; };
    return (pu(b) - pu(a)) * (pv(d) - pv(c));
  };
  ExpectCellCountsWithinJitterBound("plane", "expr:(u+0.01)*(u+0.01)*(v+0.1)", 1000000, mass,
                                    mass(0, 1, 0, 1), 4, 0.5, one_leaf);
}

TEST(Sampler, NoSampleLandsWhereTheLeafModelIsNegative) {
  // One leaf (no cell fails flatness, the error allowance is huge) whose
  // quadratic model of max(u - 0.6, 0) dips below zero for u in (0.11, 0.5):
  // the descent must clamp those sub-cells to no mass, not walk backwards.
  CurveTreeOptions one_leaf;
  one_leaf.tolerance = 10;
  one_leaf.rho = 1e12;
  const uint64_t n = 100000;
  const auto s = MakeSetup("plane", "expr:max(u-0.6,0)", n, one_leaf);
  ASSERT_EQ(s.tree->leaf_count(), 1u);
  const LeafModel& model = s.tree->leaf_model(0);
  const LeafModel::Kind kind = s.tree->leaf_model_kind(0);
  ASSERT_LT(ModelIntegral(model, kind, 2, 0.25, 0.375, 0, 1), 0) << "the model should dip";
  const SampleBatch b = Collect(MakeSampler(s, SequenceKind::kJittered, n, 3), 0, n);
  ASSERT_EQ(b.size(), n);
  const int side = 8;
  for (size_t i = 0; i < n; ++i) {
    ASSERT_TRUE(b.u[i] >= 0 && b.u[i] <= 1 && b.v[i] >= 0 && b.v[i] <= 1);
    const double cx = std::floor(b.u[i] * side) / side, cy = std::floor(b.v[i] * side) / side;
    ASSERT_GT(ModelIntegral(model, kind, 2, cx, cx + 1.0 / side, cy, cy + 1.0 / side), 0)
        << "sample " << i << " at u = " << b.u[i];
  }
}

TEST(Sampler, CountsPerCellFollowDensityUPlusVOnTheSquare) {
  auto mass = [](double a, double b, double c, double d) {
    return (b - a) * (d - c) * ((a + b) / 2 + (c + d) / 2);
  };
  ExpectCellCountsWithinJitterBound("plane", "expr:u+v", 30000, mass, 1.0, 4, 0.05);
}

TEST(Sampler, ProgressivePrefixesAreStratifiedAndExtendTheSet) {
  const uint64_t n1 = 1024, n2 = 4096;
  const auto s = MakeSetup("sphere", "uniform", n2);  // one tree sized for both
  auto small = MakeSampler(s, SequenceKind::kProgressive, n1, 4);
  auto large = MakeSampler(s, SequenceKind::kProgressive, n2, 4);
  // Every power-of-two prefix puts one q in each stratum.
  for (uint64_t m = 1; m <= n2; m *= 2) {
    std::set<uint64_t> strata;
    for (uint64_t k = 0; k < m; ++k)
      strata.insert(static_cast<uint64_t>(large->sequence().At(k) * m));
    EXPECT_EQ(strata.size(), m);
  }
  // Samples [0, n1) of the larger set are the smaller set.
  const SampleBatch a = Collect(small, 0, n1);
  const SampleBatch b = Collect(large, 0, n1);
  ExpectSameSamples(a, b);
}

TEST(Sequence, JitteredSamplesStayInTheirStrataAndAreMonotone) {
  const uint64_t n = 10000;
  Sequence seq(SequenceKind::kJittered, n, 99);
  double previous = -1;
  for (uint64_t k = 0; k < n; ++k) {
    const double q = seq.At(k);
    ASSERT_GE(q * n, static_cast<double>(k));
    ASSERT_LE(q * n, static_cast<double>(k + 1));
    ASSERT_GE(q, previous);
    previous = q;
  }
}

TEST(Sequence, AtManyGivesTheBitsOfAtForEveryKindAndWindow) {
  for (SequenceKind kind : {SequenceKind::kJittered, SequenceKind::kEqual, SequenceKind::kRandom,
                            SequenceKind::kVanDerCorput, SequenceKind::kProgressive}) {
    const Sequence plain(kind, 5000, 7);
    for (const Sequence& seq : {plain, plain.Window(0.25, 0.75)}) {
      std::vector<double> many(1000);
      seq.AtMany(3000, many.size(), many.data());
      for (size_t i = 0; i < many.size(); ++i) {
        ASSERT_EQ(many[i], seq.At(3000 + i))  // exact: no tolerance
            << SequenceName(kind) << " k " << 3000 + i;
      }
    }
  }
}

TEST(Sampler, RandomAndRadicalInverseSequencesComeOutInCurveOrder) {
  const uint64_t n = 3000;
  const auto s = MakeSetup("plane", "uniform", n);
  for (SequenceKind kind : {SequenceKind::kRandom, SequenceKind::kVanDerCorput}) {
    auto sampler = MakeSampler(s, kind, n, 1);
    SampleFields fields;
    fields.curve_position = true;
    const SampleBatch b = Collect(sampler, 0, n, {}, fields);
    ASSERT_EQ(b.size(), n);
    for (size_t i = 1; i < n; ++i) ASSERT_LE(b.curve_position[i - 1], b.curve_position[i]);
  }
}

}  // namespace
}  // namespace sfc
