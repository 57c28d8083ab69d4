// The sobol sequence and its warp through the curve tree (core/tree_warp.h):
// every 2^m block of the linearly scrambled sequence is a (0,m,2)-net; a set has
// exactly N samples in curve order, the same bytes for any batch size and
// thread count, index ranges and shards that concatenate to the whole set,
// regions that filter it, a prefix that a larger set on the same tree keeps;
// the warp keeps a density's mass split; sample means of a smooth function
// on the sphere meet the closed form at quasi-Monte Carlo rates.
#include <cmath>
#include <cstdint>
#include <random>
#include <set>
#include <utility>
#include <vector>

#include "core/sequence.h"
#include "core/tree_warp.h"
#include "core/vector_math.h"
#include "gtest/gtest.h"
#include "tests/test_util.h"

namespace sfc {
namespace {

using testing::Collect;
using testing::ExpectSameSamples;
using testing::MakeSampler;
using testing::MakeSetup;

// Every elementary box [i 2^-m1, (i+1) 2^-m1) x [j 2^-m2, (j+1) 2^-m2) with
// m1 + m2 = m holds exactly one of the 2^m points k0 .. k0 + 2^m - 1.
void ExpectNet(const Sequence& s, uint64_t k0, int m) {
  const uint64_t n = uint64_t{1} << m;
  for (int m1 = 0; m1 <= m; ++m1) {
    const int m2 = m - m1;
    std::vector<int> hits(n, 0);
    for (uint64_t k = k0; k < k0 + n; ++k) {
      const double a = s.At(k), b = s.Second(k);
      ASSERT_GE(a, 0);
      ASSERT_LT(a, 1);
      ASSERT_GE(b, 0);
      ASSERT_LT(b, 1);
      const uint64_t i = static_cast<uint64_t>(std::ldexp(a, m1));
      const uint64_t j = static_cast<uint64_t>(std::ldexp(b, m2));
      ++hits[(i << m2) | j];
    }
    for (uint64_t c = 0; c < n; ++c) ASSERT_EQ(hits[c], 1) << "m1 " << m1 << " box " << c;
  }
}

TEST(SobolSequence, EveryAlignedBlockOfTwoToTheMIsANet) {
  for (uint64_t seed : {1, 2, 99}) {
    const Sequence s(SequenceKind::kSobol, 1 << 12, seed);
    ExpectNet(s, 0, 10);
    ExpectNet(s, 1024, 10);  // the second block of 1024
    ExpectNet(s, 0, 12);
    // Blocks far along, where k's higher bytes take part.
    const Sequence all(SequenceKind::kSobol, uint64_t{1} << 32, seed);
    ExpectNet(all, uint64_t{3} << 16, 16);
    ExpectNet(all, uint64_t{0xb7} << 24, 14);
    // The scramble is more than a digital shift: a block's points do not sit
    // at one offset inside their strata, and the top ten digits are not the
    // radical inverse's xor one mask.
    const Sequence radical_inverse(SequenceKind::kVanDerCorput, 1024, seed);
    std::set<uint64_t> offsets, masks;
    for (uint64_t k = 0; k < 1024; ++k) {
      offsets.insert(static_cast<uint64_t>(std::ldexp(s.At(k), 20)) & 1023);
      masks.insert(static_cast<uint64_t>(std::ldexp(s.At(k), 10)) ^
                   static_cast<uint64_t>(std::ldexp(radical_inverse.At(k), 10)));
    }
    EXPECT_GT(offsets.size(), 1u);
    EXPECT_GT(masks.size(), 1u);
  }
  // Scrambles of other seeds differ.
  const Sequence a(SequenceKind::kSobol, 16, 1), b(SequenceKind::kSobol, 16, 2);
  EXPECT_NE(a.At(3), b.At(3));
  EXPECT_NE(a.Second(3), b.Second(3));
  // A point does not depend on the set's size.
  const Sequence c(SequenceKind::kSobol, 1 << 20, 1);
  EXPECT_EQ(a.At(5), c.At(5));
  EXPECT_EQ(a.Second(5), c.Second(5));
}

// progressive is the same nested scramble of the radical inverse with a key
// of its own: every aligned block of 2^m indices puts exactly one q in each
// [j 2^-m, (j+1) 2^-m), for levels in the flips' table (m <= 12) and in the
// hashed blocks below it; a value does not depend on the set's size; and its
// scramble is not sobol's first coordinate's.
TEST(ProgressiveSequence, EveryAlignedBlockIsStratifiedAndIndependentOfSobol) {
  for (uint64_t seed : {1, 2, 99}) {
    const Sequence s(SequenceKind::kProgressive, uint64_t{1} << 32, seed);
    for (const auto& [k0, m] : {std::pair<uint64_t, int>{0, 20}, {3 << 14, 14}, {5 << 9, 9}}) {
      const uint64_t n = uint64_t{1} << m;
      std::vector<uint8_t> hits(n, 0);
      for (uint64_t k = k0; k < k0 + n; ++k) {
        const double q = s.At(k);
        ASSERT_GE(q, 0);
        ASSERT_LT(q, 1);
        ++hits[static_cast<uint64_t>(std::ldexp(q, m))];
      }
      for (uint64_t c = 0; c < n; ++c) ASSERT_EQ(hits[c], 1) << "m " << m << " stratum " << c;
    }
    const Sequence small(SequenceKind::kProgressive, 16, seed);
    EXPECT_EQ(small.At(7), s.At(7));
    // Same digits, other flips: the top ten bits of the two scrambles do not
    // differ by one constant mask.
    const Sequence sobol(SequenceKind::kSobol, 1 << 10, seed);
    std::set<uint64_t> masks;
    for (uint64_t k = 0; k < 1024; ++k) {
      masks.insert(static_cast<uint64_t>(std::ldexp(s.At(k), 10)) ^
                   static_cast<uint64_t>(std::ldexp(sobol.At(k), 10)));
    }
    EXPECT_GT(masks.size(), 1u);
  }
  const Sequence a(SequenceKind::kProgressive, 16, 1), b(SequenceKind::kProgressive, 16, 2);
  EXPECT_NE(a.At(3), b.At(3));
}

// The batch of points (eight lanes at a time on AVX-512F) gives At's and
// Second's bits on every vector path, for index runs, index lists and
// windows, with a tail that is not a multiple of eight.
TEST(SobolSequence, PointsManyIsAtAndSecondOnEveryVectorPath) {
  const Sequence whole(SequenceKind::kSobol, uint64_t{1} << 32, 11);
  const Sequence window = whole.Window(0.25, 0.625);
  std::vector<uint32_t> ks;
  for (uint64_t k = 0; k < 1003; ++k) ks.push_back(static_cast<uint32_t>(k * 2654435761u));
  for (math::VectorPath path : math::kVectorPaths) {
    if (!math::Runs(path)) continue;
    for (const Sequence* s : {&whole, &window}) {
      for (bool listed : {false, true}) {
        std::vector<double> a(ks.size()), b(ks.size());
        const uint64_t k0 = 4000000000u;
        s->PointsMany(listed ? ks.data() : nullptr, k0, ks.size(), a.data(), b.data(), path);
        for (size_t i = 0; i < ks.size(); ++i) {
          const uint64_t k = listed ? ks[i] : k0 + i;
          ASSERT_EQ(a[i], s->At(k)) << math::VectorPathName(path) << " k " << k;
          ASSERT_EQ(b[i], s->Second(k)) << math::VectorPathName(path) << " k " << k;
        }
      }
    }
  }
}

TEST(SobolSampler, ExactCountEveryIndexOnceInCurveOrder) {
  const uint64_t n = 5000;
  const auto s = MakeSetup("torus", "gaussian:floor=0.1", n);
  SampleFields fields;
  fields.curve_position = true;
  const SampleBatch all = Collect(MakeSampler(s, SequenceKind::kSobol, n, 3), 0, n, {}, fields);
  ASSERT_EQ(all.size(), n);
  EXPECT_EQ(std::set<uint64_t>(all.index.begin(), all.index.end()).size(), n);
  for (size_t i = 1; i < n; ++i) ASSERT_LE(all.curve_position[i - 1], all.curve_position[i]) << i;
}

// Curve positions lie in [0, 1), as the column promises, also where the
// last leaf's end rounds up (superellipsoid e = 0.1: 3 of 20 000 were 1).
TEST(SobolSampler, CurvePositionsStayBelowOne) {
  const uint64_t n = 20000;
  const auto s = MakeSetup("superellipsoid:e=0.1", "uniform", n);
  SampleFields fields;
  fields.curve_position = true;
  for (SequenceKind kind : {SequenceKind::kSobol, SequenceKind::kJittered}) {
    const SampleBatch all = Collect(MakeSampler(s, kind, n, 1), 0, n, {}, fields);
    ASSERT_EQ(all.size(), n);
    for (size_t i = 0; i < n; ++i) {
      ASSERT_GE(all.curve_position[i], 0.0) << i;
      ASSERT_LT(all.curve_position[i], 1.0) << i;
    }
  }
}

// Every kind's position is CurvePosition's: the last part's end, within
// rounding of the whole, stays below 1 (a mesh of 3 triangles at 2 + (1 -
// 2^-53) of 3 rounded to 1).
TEST(CurvePosition, StaysBelowOneWhereTheQuotientRoundsUp) {
  for (double total = 1; total <= 4096; ++total) {
    // The last part's rank plus a place just below its end: the sum itself
    // rounds to total from 2 parts on.
    const double at = CurvePosition((total - 1) + math::kBelowOne, total);
    ASSERT_LT(at, 1.0) << total;
    ASSERT_GT(at, 1.0 - 0x1p-40) << total;
    ASSERT_EQ(CurvePosition(total / 2, total), 0.5);
  }
}

TEST(SobolSampler, SameBytesForAnyBatchSizeAndThreadCount) {
  const uint64_t n = 20000;
  const auto s = MakeSetup("eight", "gaussian:floor=0.1", n);
  auto sampler = MakeSampler(s, SequenceKind::kSobol, n, 5);
  const SampleBatch a = Collect(sampler, 0, n, {}, {}, 1000);
  const SampleBatch b = Collect(sampler, 0, n, {}, {}, 777);
  ExpectSameSamples(a, b);
  for (int threads : {2, 4}) {
    auto cursor = SampleCursor::Create(sampler, 0, n, {}, {}, threads);
    ASSERT_TRUE(cursor.ok()) << cursor.status();
    SampleBatch c;
    while (true) {
      auto got = (*cursor)->Next(16384, &c);
      ASSERT_TRUE(got.ok()) << got.status();
      if (*got == 0) break;
    }
    ExpectSameSamples(a, c);
  }
}

TEST(SobolSampler, RangesAndShardsArePositionsOfTheWholeSetAndRegionsFilterIt) {
  const uint64_t n = 6000;
  const auto s = MakeSetup("sphere", "expr:1+u*v", n);
  auto sampler = MakeSampler(s, SequenceKind::kSobol, n, 7);
  const SampleBatch full = Collect(sampler, 0, n);
  SampleBatch joined;
  for (uint64_t i = 0; i < 4; ++i) joined.Append(Collect(sampler, i * n / 4, (i + 1) * n / 4));
  ExpectSameSamples(joined, full);
  SampleBatch slice;
  slice.AppendFrom(full, 1234, 4321);
  ExpectSameSamples(Collect(sampler, 1234, 4321), slice);
  for (const Region& region :
       {Region::ParameterRect(0.1, 0.6, 0.2, 0.9), Region::Box({-0.5, -1, -1}, {1, 0.5, 1})}) {
    ExpectSameSamples(Collect(sampler, 0, n, region), testing::Filter(full, region));
  }
}

// A set of 2^m on a tree keeps its samples, bit for bit and in the same
// order, as the samples with index below 2^m of any larger set on that tree.
TEST(SobolSampler, ALargerSetOnTheSameTreeKeepsThePrefix) {
  const auto s = MakeSetup("torus", "uniform", 8192);
  const SampleBatch small = Collect(MakeSampler(s, SequenceKind::kSobol, 1024, 9), 0, 1024);
  const SampleBatch large = Collect(MakeSampler(s, SequenceKind::kSobol, 8192, 9), 0, 8192);
  SampleBatch prefix;
  for (size_t i = 0; i < large.size(); ++i) {
    if (large.index[i] < 1024) prefix.AppendFrom(large, i, i + 1);
  }
  ExpectSameSamples(small, prefix);
}

// The plane with density u + v: the share of the mass in u < 1/2 is 3/8, in
// [0, 0.3] x [0, 0.7] it is 0.105; a net warped by the tree meets both far
// inside a jittered set's error.
TEST(SobolSampler, KeepsTheMassSplitOfADensity) {
  const uint64_t n = 1 << 14;
  const auto s = MakeSetup("plane", "expr:u+v", n);
  for (uint64_t seed : {1, 2, 3}) {
    const SampleBatch all = Collect(MakeSampler(s, SequenceKind::kSobol, n, seed), 0, n);
    double left = 0, box = 0;
    for (size_t i = 0; i < all.size(); ++i) {
      left += all.u[i] < 0.5;
      box += all.u[i] < 0.3 && all.v[i] < 0.7;
    }
    EXPECT_NEAR(left / n, 0.375, 2e-4) << seed;
    EXPECT_NEAR(box / n, 0.105, 5e-4) << seed;
  }
}

// f = x^2 + 0.3 y z + exp(z) on the unit sphere: its mean over the area is
// (4 pi / 3 + 2 pi (e - 1/e)) / (4 pi) = 1/3 + (e - 1/e) / 2 (mean |error|
// of 3 seeds).
TEST(SobolSampler, SphereMeansMeetTheClosedFormAtQuasiMonteCarloRates) {
  const double exact = 1.0 / 3 + (std::exp(1.0) - std::exp(-1.0)) / 2;
  auto mean_error = [&](uint64_t n) {
    const auto s = MakeSetup("sphere", "uniform", n);
    double error = 0;
    for (uint64_t seed : {1, 2, 3}) {
      const SampleBatch all = Collect(MakeSampler(s, SequenceKind::kSobol, n, seed), 0, n);
      double sum = 0;
      for (size_t i = 0; i < all.size(); ++i) {
        sum += all.x[i] * all.x[i] + 0.3 * all.y[i] * all.z[i] + std::exp(all.z[i]);
      }
      error += std::fabs(sum / n - exact) / 3;
    }
    return error;
  };
  const double e10 = mean_error(1 << 10), e13 = mean_error(1 << 13), e16 = mean_error(1 << 16);
  EXPECT_LT(e13, 1.5e-5);
  // 64 times the points: the error falls by more than 64^1.25 (N^-1.25),
  // which one sample per curve stratum cannot reach (about N^-1, He and Owen 2016).
  EXPECT_LT(e16, e10 / std::pow(64.0, 1.25)) << e10 << " " << e13 << " " << e16;
}

TEST(TreeWarp, MapsTheUnitSquareOntoTheLeavesByMass) {
  // A stratified grid of the square lands in each leaf in proportion to its
  // mass: every leaf's count is within the grid cells its boundary cuts.
  const auto s = MakeSetup("monkey_saddle", "gaussian:floor=0.05", 4096);
  const CurveTree& tree = *s.tree;
  const TreeWarp warp(tree);
  const int g = 512;
  std::vector<double> hits(tree.leaf_count(), 0);
  for (int i = 0; i < g; ++i) {
    for (int j = 0; j < g; ++j) {
      const TreeWarp::Point p = warp.Map((i + 0.5) / g, (j + 0.5) / g);
      const CurveAddress at = warp.Locate((i + 0.5) / g, (j + 0.5) / g);
      ASSERT_LT(at.leaf, tree.leaf_count());
      const CurveTree::Cell c = tree.LeafCell(at.leaf);
      ASSERT_GE(p.u, c.u0);
      ASSERT_LE(p.u, c.u0 + c.size);
      ASSERT_GE(p.v, c.v0);
      ASSERT_LE(p.v, c.v0 + c.size);
      ++hits[at.leaf];
    }
  }
  double worst = 0;
  for (size_t l = 0; l < tree.leaf_count(); ++l) {
    const double expected = (tree.mass_end(l) - tree.mass_begin(l)) / tree.total_mass() * g * g;
    worst = std::max(worst, std::fabs(hits[l] - expected) / (4 * std::sqrt(expected) + 4));
  }
  EXPECT_LT(worst, 1.0);
}

// LocateMany on every vector path this CPU runs against its scalar path, bit
// for bit, at random points, the square's edges and its dyadic lines, in
// batches whose size is not a multiple of 4 or 8 (the vectors' tails).
void LocateManyMatchesScalar(const char* surface, const char* density) {
  const auto s = MakeSetup(surface, density, 1 << 14);
  const TreeWarp warp(*s.tree);
  std::mt19937_64 rng(36);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<double> a, b;
  for (int i = 0; i < 5003; ++i) a.push_back(unit(rng)), b.push_back(unit(rng));
  for (double x : {0.0, 0.25, 0.5, 0.75, 1.0, -0.5, 1.5}) {
    for (double y : {0.0, 0.5, 1.0}) a.push_back(x), b.push_back(y);
  }
  std::vector<CurveAddress> expected(a.size());
  warp.LocateMany(a.size(), a.data(), b.data(), expected.data(), math::VectorPath::kScalar);
  for (math::VectorPath path : math::kVectorPaths) {
    if (!math::Runs(path)) continue;
    for (size_t n : {size_t{1}, size_t{7}, size_t{13}, size_t{64}, size_t{70}, a.size()}) {
      std::vector<CurveAddress> got(n);
      warp.LocateMany(n, a.data(), b.data(), got.data(), path);
      for (size_t i = 0; i < n; ++i) {
        ASSERT_EQ(got[i].leaf, expected[i].leaf) << math::VectorPathName(path) << " point " << i;
        ASSERT_EQ(got[i].digits, expected[i].digits)
            << math::VectorPathName(path) << " point " << i;
      }
    }
  }
}

// The batch descent's vector paths give the scalar path's addresses: on a
// Hilbert tree with a density (leaves at several depths, so lanes reach
// their leaves in different rounds) and on the uniform sphere (quadratic
// leaves throughout: the inverse CDFs' vector code). kAvx2 runs
// core/tree_warp_avx2.cc, kAvx512 core/tree_warp_avx512.cc.
TEST(TreeWarp, LocateManyGivesTheSameAddressesOnEveryVectorPath) {
  for (const auto& [surface, density] :
       {std::pair{"monkey_saddle", "gaussian:floor=0.05"}, std::pair{"sphere", "uniform"}}) {
    SCOPED_TRACE(surface);
    LocateManyMatchesScalar(surface, density);
  }
}

}  // namespace
}  // namespace sfc
