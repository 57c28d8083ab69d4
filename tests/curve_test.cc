// Properties of the space-filling curves: bijection, edge adjacency of
// consecutive cells, start and end corners, and table consistency.
#include "core/curve.h"

#include <algorithm>
#include <array>
#include <cstdlib>
#include <random>
#include <set>
#include <vector>

#include "core/hilbert3d.h"
#include "gtest/gtest.h"

namespace sfc {
namespace {

struct Cells {
  std::vector<uint64_t> x, y;
};

// The cells of the curve at `depth` in curve order, one index at a time.
Cells Enumerate(const Curve& curve, int depth) {
  Cells cells;
  const uint64_t n = curve.PowW(depth);
  for (uint64_t i = 0; i < n; ++i) {
    uint64_t x, y;
    int state = Curve::kRootState;
    curve.Descend(i, depth, &x, &y, &state);
    cells.x.push_back(x);
    cells.y.push_back(y);
  }
  return cells;
}

class CurveTest : public ::testing::TestWithParam<CurveType> {};

TEST_P(CurveTest, IsABijectionOntoTheGridAtEveryDepth) {
  const Curve& curve = Curve::Get(GetParam());
  for (int depth = 1; depth <= (curve.grid() == 2 ? 6 : 4); ++depth) {
    const Cells cells = Enumerate(curve, depth);
    const uint64_t side = static_cast<uint64_t>(curve.PowG(depth));
    std::set<uint64_t> seen;
    for (size_t i = 0; i < cells.x.size(); ++i) {
      ASSERT_LT(cells.x[i], side);
      ASSERT_LT(cells.y[i], side);
      seen.insert(cells.x[i] * side + cells.y[i]);
    }
    EXPECT_EQ(seen.size(), side * side) << "depth " << depth;
  }
}

TEST_P(CurveTest, ConsecutiveCellsShareAnEdge) {
  const Curve& curve = Curve::Get(GetParam());
  for (int depth = 1; depth <= (curve.grid() == 2 ? 6 : 4); ++depth) {
    const Cells cells = Enumerate(curve, depth);
    for (size_t i = 1; i < cells.x.size(); ++i) {
      const int64_t dx = static_cast<int64_t>(cells.x[i]) - static_cast<int64_t>(cells.x[i - 1]);
      const int64_t dy = static_cast<int64_t>(cells.y[i]) - static_cast<int64_t>(cells.y[i - 1]);
      ASSERT_EQ(std::llabs(dx) + std::llabs(dy), 1) << "depth " << depth << " step " << i;
    }
  }
}

TEST_P(CurveTest, StartsAtTheOriginCornerAndEndsAtItsDefinedCorner) {
  const Curve& curve = Curve::Get(GetParam());
  const int depth = 3;
  const Cells cells = Enumerate(curve, depth);
  const uint64_t last = static_cast<uint64_t>(curve.PowG(depth)) - 1;
  EXPECT_EQ(cells.x.front(), 0u);
  EXPECT_EQ(cells.y.front(), 0u);
  EXPECT_EQ(cells.x.back(), last);
  EXPECT_EQ(cells.y.back(), GetParam() == CurveType::kPeano ? last : 0u);
}

// Descending in one call must equal descending digit by digit through the
// single-level table (the chunked tables are derived, this checks them).
TEST_P(CurveTest, ChunkedDescentMatchesLevelByLevel) {
  const Curve& curve = Curve::Get(GetParam());
  const int depth = curve.continuation_levels();
  uint64_t state_seed = 12345;
  for (int trial = 0; trial < 200; ++trial) {
    state_seed = state_seed * 6364136223846793005ULL + 1442695040888963407ULL;
    const uint64_t digits = state_seed % curve.PowW(depth);
    const int start_state = trial % 8;
    uint64_t x, y;
    int state = start_state;
    curve.Descend(digits, depth, &x, &y, &state);
    uint64_t ex = 0, ey = 0;
    int es = start_state;
    for (int level = depth - 1; level >= 0; --level) {
      const int digit = static_cast<int>(digits / curve.PowW(level) % curve.arity());
      const Curve::Child& ch = curve.ChildOf(es, digit);
      ex = ex * curve.grid() + ch.dx;
      ey = ey * curve.grid() + ch.dy;
      es = ch.state;
    }
    ASSERT_EQ(x, ex);
    ASSERT_EQ(y, ey);
    ASSERT_EQ(state, es);
  }
}

// Descend's fast path (bit-parallel for Hilbert) must equal the table walk
// for every start orientation and every number of levels it takes.
TEST_P(CurveTest, DescendMatchesTheTableWalkAtEveryDepth) {
  const Curve& curve = Curve::Get(GetParam());
  const int deepest = std::min(32, curve.max_depth() + curve.continuation_levels());
  uint64_t seed = 99;
  for (int levels = 0; levels <= deepest; ++levels) {
    for (int trial = 0; trial < 400; ++trial) {
      seed = seed * 6364136223846793005ULL + 1442695040888963407ULL;
      // All ones, all zeros and random digits.
      uint64_t digits = trial == 0 ? ~uint64_t{0} : trial == 1 ? 0 : seed;
      if (levels <= curve.max_depth()) digits %= curve.PowW(levels);
      if (curve.arity() != 4 && levels > curve.max_depth()) continue;  // digits past w^D
      const int start_state = trial % 8;
      uint64_t x, y, ex, ey;
      int state = start_state, es = start_state;
      curve.Descend(digits, levels, &x, &y, &state);
      curve.DescendByTables(digits, levels, &ex, &ey, &es);
      ASSERT_EQ(x, ex) << levels << " levels, digits " << digits;
      ASSERT_EQ(y, ey) << levels << " levels, digits " << digits;
      ASSERT_EQ(state, es) << levels << " levels, digits " << digits;
    }
  }
}

// The batch decoder (vectorised for Hilbert where the CPU has AVX-512F)
// gives DescendByTables' bits for every string, whatever the batch length.
TEST_P(CurveTest, DescendManyMatchesTheTableWalk) {
  const Curve& curve = Curve::Get(GetParam());
  const int levels = curve.continuation_levels();
  uint64_t seed = 7;
  for (size_t n : {size_t{1}, size_t{7}, size_t{8}, size_t{1000}, size_t{1003}}) {
    std::vector<uint64_t> digits(n), states(n), x(n), y(n);
    for (size_t i = 0; i < n; ++i) {
      seed = seed * 6364136223846793005ULL + 1442695040888963407ULL;
      digits[i] = (seed >> 11) % curve.PowW(levels);
      states[i] = i % 8;
    }
    const std::vector<uint64_t> start = states;
    curve.DescendMany(digits.data(), levels, n, states.data(), x.data(), y.data());
    for (size_t i = 0; i < n; ++i) {
      uint64_t ex, ey;
      int es = static_cast<int>(start[i]);
      curve.DescendByTables(digits[i], levels, &ex, &ey, &es);
      ASSERT_EQ(x[i], ex) << i;
      ASSERT_EQ(y[i], ey) << i;
      ASSERT_EQ(states[i], static_cast<uint64_t>(es)) << i;
    }
  }
}

TEST(CurveShapes, HilbertIIHasNoAxisOfSymmetryButPeanoIsPointSymmetric) {
  // Hilbert II's base order, mirrored in x and reversed, is not itself.
  for (CurveType type : {CurveType::kHilbert2, CurveType::kHilbert}) {
    const Curve& c = Curve::Get(type);
    const int n = c.grid();
    bool mirror_symmetric = true;
    for (int i = 0; i < c.arity(); ++i) {
      const Curve::Child& a = c.ChildOf(Curve::kRootState, i);
      const Curve::Child& b = c.ChildOf(Curve::kRootState, c.arity() - 1 - i);
      mirror_symmetric &= (a.dx == n - 1 - b.dx && a.dy == b.dy);
    }
    EXPECT_EQ(mirror_symmetric, type == CurveType::kHilbert) << CurveName(type);
  }
}

TEST(CurveNames, RoundTrip) {
  for (CurveType t : {CurveType::kHilbert, CurveType::kHilbert2, CurveType::kPeano}) {
    EXPECT_EQ(CurveFromName(CurveName(t)), t);
  }
  EXPECT_FALSE(CurveFromName("zorder").has_value());
}

INSTANTIATE_TEST_SUITE_P(AllCurves, CurveTest,
                         ::testing::Values(CurveType::kHilbert, CurveType::kHilbert2,
                                           CurveType::kPeano),
                         [](const auto& info) { return std::string(CurveName(info.param)); });

TEST(Hilbert3d, ConsecutiveKeysAreFaceAdjacentCells) {
  const int bits = 3, n = 1 << bits;
  std::vector<std::pair<uint64_t, std::array<int, 3>>> cells;
  for (int x = 0; x < n; ++x)
    for (int y = 0; y < n; ++y)
      for (int z = 0; z < n; ++z) cells.push_back({HilbertKey3(x, y, z, bits), {x, y, z}});
  std::sort(cells.begin(), cells.end());
  for (size_t i = 0; i < cells.size(); ++i) {
    ASSERT_EQ(cells[i].first, i);  // a bijection onto [0, n^3)
    if (i == 0) continue;
    const auto &a = cells[i - 1].second, &b = cells[i].second;
    EXPECT_EQ(std::abs(a[0] - b[0]) + std::abs(a[1] - b[1]) + std::abs(a[2] - b[2]), 1) << i;
  }
}

TEST(Hilbert3d, KeysOfManyPointsAreTheKeysOfEachPoint) {
  // HilbertKeys3 runs 16 lanes at a time: sizes around that, every bit count.
  std::mt19937_64 rng(5);
  for (int bits = 1; bits <= 21; ++bits) {
    for (size_t n : {size_t{1}, size_t{15}, size_t{16}, size_t{17}, size_t{100}}) {
      std::vector<uint32_t> x(n), y(n), z(n);
      for (size_t i = 0; i < n; ++i) {
        x[i] = rng() >> (64 - bits), y[i] = rng() >> (64 - bits), z[i] = rng() >> (64 - bits);
      }
      std::vector<uint64_t> keys(n);
      HilbertKeys3(n, x.data(), y.data(), z.data(), keys.data(), bits);
      for (size_t i = 0; i < n; ++i) {
        ASSERT_EQ(keys[i], HilbertKey3(x[i], y[i], z[i], bits)) << bits << " bits, point " << i;
      }
    }
  }
}

}  // namespace
}  // namespace sfc
