// Properties of the adaptive curve tree: the leaves tile the square, the
// tests that drive splitting hold at every leaf, refinement equals a fresh
// build, and budgets and depth caps are reported.
#include "core/curve_tree.h"

#include <cmath>
#include <vector>

#include "core/builtin_surfaces.h"
#include "gtest/gtest.h"
#include "tests/test_util.h"

namespace sfc {
namespace {

using testing::MakeSetup;

// Marks every leaf's cell on the finest grid the tree uses; each grid cell
// must be covered exactly once.
void ExpectLeavesTileTheSquare(const CurveTree& tree) {
  const Curve& curve = tree.curve();
  const int depth = tree.max_depth();
  ASSERT_LE(depth, curve.grid() == 2 ? 11 : 7) << "grid too fine for this check";
  const uint64_t side = static_cast<uint64_t>(curve.PowG(depth));
  std::vector<int> cover(side * side, 0);
  double area = 0;
  for (size_t l = 0; l < tree.leaf_count(); ++l) {
    const CurveTree::Cell c = tree.LeafCell(l);
    area += c.size * c.size;
    const uint64_t x0 = static_cast<uint64_t>(std::llround(c.u0 * side));
    const uint64_t y0 = static_cast<uint64_t>(std::llround(c.v0 * side));
    const uint64_t n = static_cast<uint64_t>(std::llround(c.size * side));
    for (uint64_t x = x0; x < x0 + n; ++x) {
      for (uint64_t y = y0; y < y0 + n; ++y) ++cover[x * side + y];
    }
  }
  for (int c : cover) ASSERT_EQ(c, 1);
  EXPECT_NEAR(area, 1.0, 1e-12);
}

TEST(CurveTree, LeavesTileTheSquareForEveryCurve) {
  for (CurveType type : {CurveType::kHilbert, CurveType::kHilbert2, CurveType::kPeano}) {
    CurveTreeOptions options;
    options.curve = type;
    options.tolerance = 0.05;
    const auto s = MakeSetup("monkey_saddle", "gaussian:floor=0.1", 2000, options);
    ExpectLeavesTileTheSquare(*s.tree);
    EXPECT_GT(s.tree->max_depth(), s.tree->min_depth()) << "the tree should be adaptive";
  }
}

TEST(CurveTree, EveryLeafPassesTheFlatnessTestOrSitsAtTheCap) {
  CurveTreeOptions options;
  options.tolerance = 0.02;
  options.depth_cap = 9;
  const auto s = MakeSetup("eight", "uniform", 1, options);
  for (size_t l = 0; l < s.tree->leaf_count(); ++l) {
    const CurveTree::Cell c = s.tree->LeafCell(l);
    const Vec3 centre = s.surface->Point(c.u0 + c.size / 2, c.v0 + c.size / 2);
    double spread = 0;
    for (int i = 0; i <= 2; ++i) {
      for (int j = 0; j <= 2; ++j) {
        spread = std::max(spread, Norm(s.surface->Point(c.u0 + i * c.size / 2, c.v0 + j * c.size / 2) - centre));
      }
    }
    if (c.depth < options.depth_cap) ASSERT_LE(spread, options.tolerance) << "leaf " << l;
  }
}

TEST(CurveTree, NoLeafBelowTheCapCarriesMoreThanRhoSamplesOfMass) {
  for (double rho : {1.0, 4.0}) {
    CurveTreeOptions options;
    options.rho = rho;
    const uint64_t n = 5000;
    const auto s = MakeSetup("sphere", "expr:1+10*u", n, options);
    const double limit = rho * s.tree->base_mass() / std::ldexp(1.0, s.tree->grade());
    for (size_t l = 0; l < s.tree->leaf_count(); ++l) {
      ASSERT_LE(s.tree->mass_end(l) - s.tree->mass_begin(l), limit * (1 + 1e-12));
    }
    // ... which is at most rho samples' worth for this N (S_base ~ S_M).
    EXPECT_LE(limit / s.tree->total_mass() * n, rho * 1.01);
  }
}

TEST(CurveTree, RefiningACachedTreeEqualsBuildingAFreshOne) {
  for (AreaEstimator e : {AreaEstimator::kFirstFundamentalForm, AreaEstimator::kTriangle,
                          AreaEstimator::kQuadrature}) {
    CurveTreeOptions options;
    options.estimator = e;
    const auto coarse = MakeSetup("torus", "gaussian:floor=0.2", 100, options);
    const auto fresh = MakeSetup("torus", "gaussian:floor=0.2", 20000, options);
    auto refined = coarse.tree->Refined(*coarse.surface, *coarse.density, fresh.tree->grade());
    ASSERT_TRUE(refined.ok()) << refined.status();
    ASSERT_EQ((*refined)->leaf_count(), fresh.tree->leaf_count());
    EXPECT_GT(fresh.tree->leaf_count(), coarse.tree->leaf_count());
    for (size_t l = 0; l < fresh.tree->leaf_count(); ++l) {
      ASSERT_EQ((*refined)->leaf_start(l), fresh.tree->leaf_start(l));
      ASSERT_EQ((*refined)->mass_end(l), fresh.tree->mass_end(l));  // bit-identical
    }
  }
}

TEST(CurveTree, LeafBudgetIsResourceExhausted) {
  auto sphere = MakeSphere(1);
  auto uniform = MakeUniformDensity();
  CurveTreeOptions options;
  options.max_leaves = 1000;
  auto tree = CurveTree::Build(*sphere, *uniform, options, CurveTree::GradeFor(100000));
  ASSERT_EQ(tree.status().code(), absl::StatusCode::kResourceExhausted);
  EXPECT_NE(tree.status().message().find("max_leaves"), std::string::npos);
}

TEST(CurveTree, DepthCapHitsAreReportedWithPlaceAndExcess) {
  // The superellipsoid with e = 1/3 is the paper's precision-limit example.
  CurveTreeOptions options;
  options.depth_cap = 8;
  options.tolerance = 0.05;
  const auto s = MakeSetup("superellipsoid", "uniform", 1000, options);
  const PrecisionReport& report = s.tree->precision();
  EXPECT_GT(report.geometry_capped_leaves, 0u);
  ASSERT_FALSE(report.worst.empty());
  const DepthCapHit& worst = report.worst.front();
  EXPECT_GT(worst.measured, worst.limit);
  EXPECT_DOUBLE_EQ(worst.size, std::ldexp(1.0, -8));
  for (size_t i = 1; i < report.worst.size(); ++i) {
    EXPECT_GE(report.worst[i - 1].measured / report.worst[i - 1].limit,
              report.worst[i].measured / report.worst[i].limit);
  }
  // With the power-law reparameterisation the same cap leaves fewer cells
  // short, and none by as much.
  const auto r = MakeSetup("superellipsoid:reparam=1", "uniform", 1000, options);
  const PrecisionReport& rr = r.tree->precision();
  EXPECT_LT(rr.geometry_capped_leaves, report.geometry_capped_leaves);
  if (!rr.worst.empty()) {
    EXPECT_LT(rr.worst.front().measured, worst.measured);
  }
}

TEST(CurveTree, BadInputIsInvalidArgument) {
  auto plane = MakePlane();
  auto uniform = MakeUniformDensity();
  CurveTreeOptions bad;
  bad.rho = 0;
  EXPECT_EQ(CurveTree::Build(*plane, *uniform, bad, 3).status().code(),
            absl::StatusCode::kInvalidArgument);
  bad = {};
  bad.depth_cap = 40;
  EXPECT_EQ(CurveTree::Build(*plane, *uniform, bad, 3).status().code(),
            absl::StatusCode::kInvalidArgument);
  bad = {};
  bad.tolerance = -1;
  EXPECT_EQ(CurveTree::Build(*plane, *uniform, bad, 3).status().code(),
            absl::StatusCode::kInvalidArgument);
}

TEST(CurveTree, GradeIsTheCeilingOfLog2) {
  EXPECT_EQ(CurveTree::GradeFor(1), 0);
  EXPECT_EQ(CurveTree::GradeFor(2), 1);
  EXPECT_EQ(CurveTree::GradeFor(1000), 10);
  EXPECT_EQ(CurveTree::GradeFor(1024), 10);
  EXPECT_EQ(CurveTree::GradeFor(1025), 11);
}

}  // namespace
}  // namespace sfc
