// Region requests return exactly the samples of the full set inside the
// region (same indices, same bytes), on surfaces whose patches oscillate
// between the tree's probe points, on random expression surfaces, and on a
// surface without bounds; and regions are validated.
#include <cmath>
#include <random>
#include <string>

#include "core/sampler.h"
#include "core/types/region.h"
#include "gtest/gtest.h"
#include "tests/test_util.h"

namespace sfc {
namespace {

using testing::Collect;
using testing::ExpectSameSamples;
using testing::Filter;
using testing::MakeSampler;
using testing::MakeSetup;

// Random boxes inside (and around) the full set's bounding box, and random
// parameter rectangles; each region request must equal the filtered set.
// Returns how many regions held at least one sample.
int CheckRandomRegions(const std::shared_ptr<const Sampler>& sampler, const SampleBatch& full,
                       uint64_t n, int regions, uint64_t seed, SampleFields fields = {}) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  Vec3 lo{INFINITY, INFINITY, INFINITY}, hi{-INFINITY, -INFINITY, -INFINITY};
  for (size_t i = 0; i < full.size(); ++i) {
    lo = {std::min(lo.x, full.x[i]), std::min(lo.y, full.y[i]), std::min(lo.z, full.z[i])};
    hi = {std::max(hi.x, full.x[i]), std::max(hi.y, full.y[i]), std::max(hi.z, full.z[i])};
  }
  int nonempty = 0;
  for (int r = 0; r < regions; ++r) {
    Region region;
    if (r % 3 == 2) {
      const double w = 0.05 + 0.6 * unit(rng), h = 0.05 + 0.6 * unit(rng);
      const double u0 = unit(rng) * (1 - w), v0 = unit(rng) * (1 - h);
      region = Region::ParameterRect(u0, u0 + w, v0, v0 + h);
    } else {
      auto axis = [&](double a, double b, double* l, double* u) {
        const double span = std::max(b - a, 1e-9);
        const double w = span * (0.05 + 0.7 * unit(rng));
        *l = a - 0.1 * span + unit(rng) * (span * 1.2 - w);
        *u = *l + w;
      };
      Vec3 bl, bh;
      axis(lo.x, hi.x, &bl.x, &bh.x);
      axis(lo.y, hi.y, &bl.y, &bh.y);
      axis(lo.z, hi.z, &bl.z, &bh.z);
      region = Region::Box(bl, bh);
    }
    const SampleBatch expected = Filter(full, region);
    nonempty += expected.size() > 0;
    const SampleBatch got = Collect(sampler, 0, n, region, fields);
    ExpectSameSamples(got, expected);
    if (::testing::Test::HasFatalFailure()) return nonempty;
  }
  return nonempty;
}

// The case: z = sin(8 pi u) peaks between the tree's probe points;
// the box above z = 0.8 holds about a tenth of the set.
TEST(RegionRequest, OscillatingSurfaceBoxHoldsExactlyTheFilteredSamples) {
  const uint64_t n = 10000;
  const auto s = MakeSetup("expr:x=u;y=v;z=sin(8*_pi*u)", "uniform", n);
  auto sampler = MakeSampler(s, SequenceKind::kJittered, n, 1);
  const SampleBatch full = Collect(sampler, 0, n);
  const Region box = Region::Box({0, 0, 0.8}, {1, 1, 1});
  const SampleBatch expected = Filter(full, box);
  EXPECT_GT(expected.size(), n / 20);
  ExpectSameSamples(Collect(sampler, 0, n, box), expected);
  // Thin slabs at the crests and troughs, and index sub-ranges.
  for (const Region& r : {Region::Box({-1, -1, 0.999}, {2, 2, 2}),
                          Region::Box({-1, -1, -2}, {2, 2, -0.9995}),
                          Region::Box({0.3, 0.2, -0.1}, {0.7, 0.9, 0.1})}) {
    const SampleBatch e = Filter(full, r);
    EXPECT_GT(e.size(), 0u);
    ExpectSameSamples(Collect(sampler, 0, n, r), e);
    SampleBatch slice;
    slice.AppendFrom(full, 2000, 7000);
    ExpectSameSamples(Collect(sampler, 2000, 7000, r), Filter(slice, r));
  }
  EXPECT_GT(CheckRandomRegions(sampler, full, n, 40, 2), 20);
}

// The 3x3 curves cut cells of side 3^-k, which are not exact in binary.
TEST(RegionRequest, ThreeByThreeCurvesHoldExactlyTheFilteredSamples) {
  const uint64_t n = 6000;
  for (CurveType curve : {CurveType::kPeano, CurveType::kHilbert2}) {
    CurveTreeOptions options;
    options.curve = curve;
    const auto s = MakeSetup("expr:x=u;y=v;z=sin(8*_pi*u)*cos(5*v)", "uniform", n, options);
    auto sampler = MakeSampler(s, SequenceKind::kJittered, n, 4);
    const SampleBatch full = Collect(sampler, 0, n);
    EXPECT_GT(CheckRandomRegions(sampler, full, n, 30, 8), 15);
    // Rectangles on the curve's own cell edges, 1/3 and 2/3 rounded.
    for (const Region& r : {Region::ParameterRect(1.0 / 3, 2.0 / 3, 1.0 / 3, 2.0 / 3),
                            Region::ParameterRect(0, 1.0 / 9, 0, 1),
                            Region::ParameterRect(2.0 / 3, 1, 4.0 / 9, 5.0 / 9)}) {
      ExpectSameSamples(Collect(sampler, 0, n, r), Filter(full, r));
    }
  }
}

TEST(RegionRequest, BuiltInSurfacesHoldExactlyTheFilteredSamples) {
  const uint64_t n = 6000;
  int seed = 0;
  for (const char* spec : {"sphere", "torus", "eight", "superellipsoid:reparam=1"}) {
    const auto s = MakeSetup(spec, "uniform", n);
    auto sampler = MakeSampler(s, SequenceKind::kJittered, n, 3);
    const SampleBatch full = Collect(sampler, 0, n);
    EXPECT_GT(CheckRandomRegions(sampler, full, n, 24, ++seed), 12) << spec;
  }
}

// A random continuous expression in u and v, finite on the unit square.
std::string RandomExpression(std::mt19937_64& rng, int depth) {
  std::uniform_int_distribution<int> pick(0, depth <= 0 ? 2 : 14);
  std::uniform_real_distribution<double> c(-2, 2);
  auto sub = [&] { return RandomExpression(rng, depth - 1); };
  switch (pick(rng)) {
    case 0:
      return "u";
    case 1:
      return "v";
    case 2:
      return std::to_string(c(rng));
    case 3:
      return "sin(" + std::to_string(2 + 4 * std::fabs(c(rng))) + "*" + sub() + ")";
    case 4:
      return "cos(" + sub() + ")";
    case 5:
      return "atan(" + sub() + ")";
    case 6:
      return "(" + sub() + ")^2";
    case 7:
      return "(" + sub() + ")^3";
    case 8:
      return "sqrt(1 + (" + sub() + ")^2)";
    case 9:
      return "(" + sub() + " + " + sub() + ")";
    case 10:
      return "(" + sub() + " - " + sub() + ")";
    case 11:
      return "(" + sub() + " * " + sub() + ")";
    case 12:
      return "min(" + sub() + ", " + sub() + ")";
    case 13:
      return "abs(" + sub() + ")";
    default: {
      // Continuous conditionals only: the tree refines without end at jumps.
      const std::string a = sub(), b = sub();
      return "(" + a + " < " + b + " ? " + a + " : " + b + ")";
    }
  }
}

TEST(RegionRequest, RandomExpressionSurfacesHoldExactlyTheFilteredSamples) {
  std::mt19937_64 rng(77);
  const uint64_t n = 4000;
  for (int i = 0; i < 6; ++i) {
    const std::string spec = "expr:x=u + 0.3*" + RandomExpression(rng, 3) + ";y=v + 0.3*" +
                             RandomExpression(rng, 3) + ";z=" + RandomExpression(rng, 3);
    SCOPED_TRACE(spec);
    const auto s = MakeSetup(spec, "uniform", n);
    ASSERT_NE(s.tree, nullptr);
    auto sampler = MakeSampler(s, SequenceKind::kJittered, n, i);
    const SampleBatch full = Collect(sampler, 0, n);
    CheckRandomRegions(sampler, full, n, 30, 100 + i);
    // With normals the samples come from Jet, whose points are Point's.
    SampleFields normals;
    normals.normal = true;
    CheckRandomRegions(sampler, Collect(sampler, 0, n, {}, normals), n, 6, 200 + i, normals);
  }
}

// Without Surface::Bound every sample is tested: still exactly the filter.
class NoBoundSurface final : public Surface {
 public:
  Vec3 Point(double u, double v) const override {
    return {u, v, std::sin(20 * u) * std::cos(13 * v)};
  }
};

TEST(RegionRequest, SurfacesWithoutBoundsAreFilteredSampleBySample) {
  const uint64_t n = 5000;
  testing::Setup s;
  s.surface = std::make_shared<NoBoundSurface>();
  s.density = MakeUniformDensity();
  auto tree = CurveTree::Build(*s.surface, *s.density, {}, CurveTree::GradeFor(n));
  ASSERT_TRUE(tree.ok()) << tree.status();
  s.tree = *tree;
  auto sampler = MakeSampler(s, SequenceKind::kJittered, n, 5);
  const SampleBatch full = Collect(sampler, 0, n);
  EXPECT_GT(CheckRandomRegions(sampler, full, n, 20, 9), 10);
}

TEST(Region, ParameterRectanglesMustLieInTheUnitSquare) {
  for (const Region& bad :
       {Region::ParameterRect(-0.1, 0.5, 0, 1), Region::ParameterRect(0.5, 1.2, 0, 1),
        Region::ParameterRect(0, 1, -1, 0.5), Region::ParameterRect(0, 1, 0.5, 2)}) {
    const absl::Status st = bad.Validate();
    EXPECT_EQ(st.code(), absl::StatusCode::kInvalidArgument);
    EXPECT_NE(std::string(st.message()).find("unit square"), std::string::npos) << st;
  }
  EXPECT_TRUE(Region::ParameterRect(0, 1, 0, 1).Validate().ok());
  EXPECT_TRUE(Region::ParameterRect(0.25, 0.5, 0.5, 0.75).Validate().ok());
  EXPECT_FALSE(Region::ParameterRect(0.5, 0.5, 0, 1).Validate().ok());
  EXPECT_FALSE(Region::ParameterRect(NAN, 0.5, 0, 1).Validate().ok());
  EXPECT_FALSE(Region::Box({0, 0, 0}, {1, 1, 0}).Validate().ok());
}

}  // namespace
}  // namespace sfc
