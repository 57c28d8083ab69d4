// The walk is a pure function of the mass coordinate: its per-level cache
// never shows in the result, whatever order or grouping the coordinates come
// in, on every curve and on models of both kinds.
#include "core/leaf_walk.h"

#include <algorithm>
#include <cstring>
#include <random>
#include <vector>

#include "gtest/gtest.h"
#include "tests/test_util.h"

namespace sfc {
namespace {

using testing::MakeSetup;

struct Placed {
  std::vector<double> u, v, position;
};

// Places m[order[i]] one group at a time, the groups cut at `cuts`.
Placed PlaceInGroups(const testing::Setup& setup, const std::vector<double>& m,
                     const std::vector<size_t>& order, const std::vector<size_t>& cuts) {
  LeafWalk walk(*setup.tree, *setup.surface, *setup.density);
  Placed out;
  out.u.assign(m.size(), 0), out.v.assign(m.size(), 0), out.position.assign(m.size(), 0);
  std::vector<double> group, u, v, position;
  size_t begin = 0;
  for (size_t end : cuts) {
    group.clear();
    for (size_t i = begin; i < end; ++i) group.push_back(m[order[i]]);
    u.resize(group.size()), v.resize(group.size()), position.resize(group.size());
    walk.Place(group.data(), group.size(), u.data(), v.data(), position.data());
    for (size_t i = begin; i < end; ++i) {
      out.u[order[i]] = u[i - begin];
      out.v[order[i]] = v[i - begin];
      out.position[order[i]] = position[i - begin];
    }
    begin = end;
  }
  return out;
}

void ExpectBitIdentical(const std::vector<double>& a, const std::vector<double>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(std::memcmp(&a[i], &b[i], sizeof(double)), 0) << "coordinate " << i;
  }
}

TEST(LeafWalk, PlacementIsAPureFunctionOfTheMassCoordinate) {
  const uint64_t n = 20000;
  struct Case {
    const char* surface;
    const char* density;
    CurveType curve;
  };
  // The superellipsoid with a small exponent has singular leaves: piecewise models.
  for (const Case& c : {Case{"torus", "uniform", CurveType::kHilbert},
                        Case{"eight", "gaussian:floor=0.1", CurveType::kHilbert2},
                        Case{"sphere", "mean", CurveType::kPeano},
                        Case{"superellipsoid:e=0.2", "uniform", CurveType::kHilbert}}) {
    SCOPED_TRACE(c.surface);
    CurveTreeOptions options;
    options.curve = c.curve;
    const auto setup = MakeSetup(c.surface, c.density, n, options);
    const CurveTree& tree = *setup.tree;
    // Jittered coordinates in curve order, plus both ends of the curve.
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> jitter(0, 1);
    std::vector<double> m;
    for (uint64_t k = 0; k < n; ++k) m.push_back((k + jitter(rng)) / n * tree.total_mass());
    m.front() = 0, m.back() = tree.total_mass();

    std::vector<size_t> in_order(m.size());
    for (size_t i = 0; i < m.size(); ++i) in_order[i] = i;
    const Placed whole = PlaceInGroups(setup, m, in_order, {m.size()});

    // One at a time, and in random groups: the same bits.
    std::vector<size_t> singles(m.size()), random_cuts;
    for (size_t i = 0; i < m.size(); ++i) singles[i] = i + 1;
    for (size_t at = 0; at < m.size();) {
      at = std::min(m.size(), at + 1 + rng() % 700);
      random_cuts.push_back(at);
    }
    // Shuffled: every step may go back and start a search.
    std::vector<size_t> shuffled = in_order;
    std::shuffle(shuffled.begin(), shuffled.end(), rng);
    for (const Placed& other : {PlaceInGroups(setup, m, in_order, singles),
                                PlaceInGroups(setup, m, in_order, random_cuts),
                                PlaceInGroups(setup, m, shuffled, random_cuts)}) {
      ExpectBitIdentical(whole.u, other.u);
      ExpectBitIdentical(whole.v, other.v);
      ExpectBitIdentical(whole.position, other.position);
    }
    // Curve order in, curve order out; every sample inside the unit square.
    for (size_t i = 0; i < m.size(); ++i) {
      ASSERT_TRUE(whole.u[i] >= 0 && whole.u[i] <= 1 && whole.v[i] >= 0 && whole.v[i] <= 1) << i;
      if (i > 0) ASSERT_LE(whole.position[i - 1], whole.position[i]) << i;
    }
  }
}

// Inside a table cell a sample follows the mass's slope (LeafWalk,
// FollowSlope). Under a linear density every leaf's quadratic is exact, and
// so is each cell's linear density, so finely spaced mass coordinates give
// the density's mean of u to far below the bias of a uniform placement
// inside the cells (about h^2 / 12 of the relative slope 3 / (1 + 3u), ~7e-6
// at the cells of side 1/128 that leaves of one sample at grade 2^12 get).
TEST(LeafWalk, InsideACellSamplesFollowTheMassSlope) {
  const auto setup = MakeSetup("plane", "expr:1+3*u", 4096);
  LeafWalk walk(*setup.tree, *setup.surface, *setup.density);
  const size_t n = size_t{1} << 20;
  std::vector<double> m(n), u(n), v(n);
  for (size_t i = 0; i < n; ++i) m[i] = (i + 0.5) / n * setup.tree->total_mass();
  walk.Place(m.data(), n, u.data(), v.data(), nullptr);
  double mean_u = 0, mean_v = 0;
  for (size_t i = 0; i < n; ++i) mean_u += u[i], mean_v += v[i];
  mean_u /= n, mean_v /= n;
  // int u (1 + 3u) / int (1 + 3u) = (1/2 + 1) / (1 + 3/2).
  EXPECT_NEAR(mean_u, 0.6, 1e-6);
  EXPECT_NEAR(mean_v, 0.5, 1e-6);
}

}  // namespace
}  // namespace sfc
