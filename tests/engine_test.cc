// Request validation end to end: every bad input gives a clear error with the
// right code, never a crash; the catalogue builds every surface it lists.
#include "engine/sampling_engine.h"

#include <cmath>

#include "catalog/catalog.h"
#include "core/builtin_surfaces.h"
#include "gtest/gtest.h"
#include "kinds/registered_kinds.h"
#include "request/index_range.h"
#include "request/routing_key.h"

namespace sfc {
namespace {

absl::StatusOr<SamplingJob> StartWith(const std::string& surface, const std::string& density,
                                      uint64_t count, EngineLimits limits = {}) {
  static DirectTreeSource source;
  SamplingEngine engine(RegisteredSurfaceKinds(), limits, &source);
  SampleRequest r;
  r.tree.surface = surface;
  r.tree.density = density;
  r.count = count;
  return engine.Start(r);
}

// Starts the job and reads it to the end; returns the first error.
absl::Status RunToEnd(const std::string& surface, const std::string& density, uint64_t count) {
  auto job = StartWith(surface, density, count);
  if (!job.ok()) return job.status();
  SampleBatch batch;
  while (true) {
    batch.Clear();
    auto n = job->cursor->Next(4096, &batch);
    if (!n.ok()) return n.status();
    if (*n == 0) return absl::OkStatus();
  }
}

void ExpectError(const absl::Status& status, absl::StatusCode code, const std::string& mentions) {
  EXPECT_EQ(status.code(), code) << status;
  EXPECT_NE(status.message().find(mentions), std::string::npos)
      << "message \"" << status.message() << "\" should mention \"" << mentions << "\"";
}

TEST(Engine, SurfaceThatIsNotFiniteIsInvalidArgument) {
  ExpectError(RunToEnd("expr:x=u;y=v;z=sqrt(u-0.5)", "uniform", 100),
              absl::StatusCode::kInvalidArgument, "not finite");
}

TEST(Engine, ASingularityExhaustsTheLeafBudgetAndIsLocated) {
  EngineLimits limits;
  limits.max_tree_leaves = 20000;
  // A pole along u = 0.3: the area grows without bound as the tree refines
  // there, until the budget.
  const absl::Status status =
      StartWith("expr:x=u;y=v;z=1/(u-0.3)", "uniform", 1000000, limits).status();
  ExpectError(status, absl::StatusCode::kResourceExhausted, "max_leaves");
  const std::string marker = "(u,v) = (";
  const size_t at = status.message().find(marker);
  ASSERT_NE(at, std::string::npos) << status;
  EXPECT_NEAR(std::atof(std::string(status.message().substr(at + marker.size())).c_str()), 0.3,
              0.01);
}

// The leaf budget's error says what fills it: a short request on a surface
// of fine detail is not told to ask for fewer samples; a large one is.
TEST(Engine, ALeafBudgetErrorSaysWhetherTheCountOrTheDetailFillsIt) {
  EngineLimits limits;
  limits.max_tree_leaves = 8192;
  const std::string ripples = "expr:x=u;y=v;z=0.1*abs(sin(3000*u))";
  const absl::Status detail = StartWith(ripples, "uniform", 100, limits).status();
  ExpectError(detail, absl::StatusCode::kResourceExhausted, "the count is not what needs them");
  EXPECT_EQ(detail.message().find("fewer samples"), std::string::npos) << detail;
  ExpectError(StartWith("torus", "uniform", 100'000'000, limits).status(),
              absl::StatusCode::kResourceExhausted, "ask for fewer samples");
}

TEST(Engine, NegativeDensityIsInvalidArgument) {
  ExpectError(RunToEnd("plane", "expr:u-0.5", 100), absl::StatusCode::kInvalidArgument, ">= 0");
}

TEST(Engine, ZeroTotalMassIsInvalidArgument) {
  ExpectError(RunToEnd("plane", "expr:0", 100), absl::StatusCode::kInvalidArgument, "integrates");
  // A plane has no curvature: |K| integrates to zero without a floor.
  ExpectError(RunToEnd("plane", "gaussian", 100), absl::StatusCode::kInvalidArgument, "floor");
}

TEST(Engine, MalformedExpressionNamesThePosition) {
  ExpectError(RunToEnd("expr:x=u;y=v;z=u**v", "uniform", 10), absl::StatusCode::kInvalidArgument,
              "position 2");
  ExpectError(RunToEnd("plane", "expr:u+w", 10), absl::StatusCode::kInvalidArgument, "w");
  ExpectError(RunToEnd("expr:x=u;y=v", "uniform", 10), absl::StatusCode::kInvalidArgument,
              "needs the parameter z");
}

TEST(Engine, CountOfZeroOrAboveTheLimitIsInvalidArgument) {
  ExpectError(StartWith("sphere", "uniform", 0).status(), absl::StatusCode::kInvalidArgument,
              "count");
  EngineLimits limits;
  limits.max_count = 1000;
  ExpectError(StartWith("sphere", "uniform", 1001, limits).status(),
              absl::StatusCode::kInvalidArgument, "max_count");
}

// max_count bounds what one request delivers, not N: index ranges and shards
// of a set far larger than it are served (each costs its own samples), and
// N itself is bounded by max_set_count.
TEST(Engine, RangesOfASetLargerThanARequestAreServed) {
  DirectTreeSource source;
  EngineLimits limits;
  limits.max_count = 1000;
  limits.max_set_count = 1'000'000'000;
  SamplingEngine engine(RegisteredSurfaceKinds(), limits, &source);
  SampleRequest r;
  r.tree.surface = "torus";
  r.count = 1'000'000'000;
  r.seed = 1;
  r.begin = 123'456'789;
  r.end = r.begin + 1000;
  absl::StatusOr<SamplingJob> job = engine.Start(r);
  ASSERT_TRUE(job.ok()) << job.status();
  EXPECT_EQ(job->end - job->begin, 1000u);
  r.end = r.begin + 1001;
  ExpectError(engine.Start(r).status(), absl::StatusCode::kInvalidArgument, "max_count");
  r.begin = r.end = 0;
  r.shard_count = 1'000'000;
  r.shard_index = 999'999;
  EXPECT_TRUE(engine.Start(r).ok());
  r.shard_count = r.shard_index = 0;
  r.count = limits.max_set_count + 1;
  r.begin = 0, r.end = 10;
  ExpectError(engine.Start(r).status(), absl::StatusCode::kInvalidArgument, "max_set_count");
}

TEST(Engine, UnknownSurfaceDensityOrParameterIsInvalidArgument) {
  ExpectError(StartWith("klein", "uniform", 10).status(), absl::StatusCode::kInvalidArgument,
              "known: plane");
  ExpectError(StartWith("sphere", "curvy", 10).status(), absl::StatusCode::kInvalidArgument,
              "unknown density");
  ExpectError(StartWith("sphere:radius=2", "uniform", 10).status(),
              absl::StatusCode::kInvalidArgument, "accepted: r");
  ExpectError(StartWith("torus:r=-1", "uniform", 10).status(), absl::StatusCode::kInvalidArgument,
              "> 0");
  ExpectError(StartWith("sphere:r=1;r=2", "uniform", 10).status(),
              absl::StatusCode::kInvalidArgument, "given twice");
}

TEST(Engine, OverlongSpecIsInvalidArgument) {
  EngineLimits limits;
  limits.max_spec_length = 64;
  ExpectError(StartWith("expr:x=u;y=v;z=" + std::string(100, '1'), "uniform", 10, limits).status(),
              absl::StatusCode::kInvalidArgument, "max_spec_length");
}

TEST(Engine, BadRangeShardOrRegionIsInvalidArgument) {
  DirectTreeSource source;
  SamplingEngine engine(RegisteredSurfaceKinds(), {}, &source);
  SampleRequest r;
  r.count = 100;
  r.begin = 50;
  r.end = 40;
  ExpectError(engine.Start(r).status(), absl::StatusCode::kInvalidArgument, "begin <= end");
  r = {};
  r.count = 100;
  r.shard_index = 3;
  r.shard_count = 3;
  ExpectError(engine.Start(r).status(), absl::StatusCode::kInvalidArgument, "shard");
  r = {};
  r.count = 100;
  r.region = Region::ParameterRect(0.5, 0.5, 0, 1);
  ExpectError(engine.Start(r).status(), absl::StatusCode::kInvalidArgument, "empty");
  r.region = Region::Box({0, 0, 0}, {1, -1, 1});
  ExpectError(engine.Start(r).status(), absl::StatusCode::kInvalidArgument, "empty");
}

TEST(Engine, AModelSpecIsAModelNotAnUnknownSurface) {
  if (!RegisteredSurfaceKinds().For(ModelSpec{ModelFormat::kObj, "x", ""})) {
    GTEST_SKIP() << "this build has no mesh kind (tests/surface_kind_test.cc covers its refusal)";
  }
  DirectTreeSource source;
  FileModelSource files;
  SamplingEngine engine(RegisteredSurfaceKinds(), {}, &source, &files);
  SampleRequest r;
  r.count = 10;
  r.tree.surface = "obj:/nonexistent/part.obj";
  ExpectError(engine.Start(r).status(), absl::StatusCode::kInvalidArgument, "part.obj");
  r.tree.surface = "ply:sha256=12";
  ExpectError(engine.Start(r).status(), absl::StatusCode::kInvalidArgument, "SHA-256");
}

TEST(Engine, ATreeSizedForFewerSamplesThanTheSetIsRefused) {
  DirectTreeSource source;
  SamplingEngine engine(RegisteredSurfaceKinds(), {}, &source);
  SampleRequest r;
  r.tree.surface = "plane";
  r.count = 5000;
  r.tree_count = 4999;
  ExpectError(engine.Start(r).status(), absl::StatusCode::kInvalidArgument, "tree_count");
  r.tree_count = 5000;
  EXPECT_TRUE(engine.Start(r).ok());
  r.tree_count = 0;  // sized for count
  EXPECT_TRUE(engine.Start(r).ok());
}

TEST(Engine, UnorderedSequencesAreBoundedPerRequest) {
  DirectTreeSource source;
  EngineLimits limits;
  limits.max_sorted_range = 1000;
  SamplingEngine engine(RegisteredSurfaceKinds(), limits, &source);
  SampleRequest r;
  r.tree.surface = "plane";
  r.count = 5000;
  r.sequence = SequenceKind::kRandom;
  ExpectError(engine.Start(r).status(), absl::StatusCode::kInvalidArgument, "max_sorted_range");
  r.begin = 1000;
  r.end = 2000;
  EXPECT_TRUE(engine.Start(r).ok());
}

// A sobol set sorts its whole count for every request: a range of it does not
// escape the bound, and a count within it is served.
TEST(Engine, SobolSetsAreBoundedByTheirWholeCount) {
  DirectTreeSource source;
  EngineLimits limits;
  limits.max_sorted_range = 1000;
  limits.max_set_count = uint64_t{1} << 40;  // N past 2^32 meets the sequence's own limit
  SamplingEngine engine(RegisteredSurfaceKinds(), limits, &source);
  SampleRequest r;
  r.tree.surface = "plane";
  r.count = 5000;
  r.sequence = SequenceKind::kSobol;
  r.begin = 1000;
  r.end = 1500;
  ExpectError(engine.Start(r).status(), absl::StatusCode::kInvalidArgument, "whole set");
  r.count = 1000;
  r.begin = r.end = 0;
  EXPECT_TRUE(engine.Start(r).ok());
  r.count = (uint64_t{1} << 32) + 1;
  ExpectError(engine.Start(r).status(), absl::StatusCode::kInvalidArgument, "2^32");
}

TEST(Engine, ShardsPartitionTheIndexRange) {
  SampleRequest r;
  r.count = 1001;
  r.shard_count = 8;
  uint64_t expected_begin = 0;
  for (uint64_t i = 0; i < 8; ++i) {
    r.shard_index = i;
    auto range = ResolveIndexRange(r);
    ASSERT_TRUE(range.ok());
    EXPECT_EQ(range->first, expected_begin);
    expected_begin = range->second;
  }
  EXPECT_EQ(expected_begin, 1001u);
}

TEST(Catalog, EveryListedSurfaceSamplesWithEveryBuiltInDensity) {
  for (const CatalogEntry& e : SurfaceCatalog()) {
    const std::string spec = e.name == "expr"             ? "expr:x=u;y=v;z=u*v"
                             : e.name == "superellipsoid" ? "superellipsoid:reparam=1"
                                                          : e.name;
    for (const char* density : {"uniform", "gaussian:floor=0.1", "mean:floor=0.1", "expr:1+x*x"}) {
      EXPECT_TRUE(RunToEnd(spec, density, 500).ok()) << spec << " " << density;
    }
  }
}

TEST(Catalog, CanonicalSpecsIgnoreSpellingButNotValues) {
  auto a = MakeSurface("torus:R=2;r=0.5");
  auto b = MakeSurface(" torus:r=1/2; R=4/2 ");
  auto c = MakeSurface("torus:R=2;r=0.6");
  ASSERT_TRUE(a.ok() && b.ok() && c.ok());
  EXPECT_EQ(a->canonical, b->canonical);
  EXPECT_NE(a->canonical, c->canonical);
}

// The closed-form derivatives of the built-in surfaces agree with finite
// differences of their positions (the base class's numeric jet).
TEST(Surfaces, AnalyticJetsAgreeWithFiniteDifferences) {
  class Numeric final : public Surface {
   public:
    explicit Numeric(const Surface& s) : s_(s) {}
    Vec3 Point(double u, double v) const override { return s_.Point(u, v); }

   private:
    const Surface& s_;
  };
  for (const char* spec : {"sphere:r=1.5", "torus", "monkey_saddle", "eight", "whitney"}) {
    auto s = MakeSurface(spec);
    ASSERT_TRUE(s.ok());
    Numeric numeric(*s->surface);
    for (double u : {0.13, 0.5, 0.77}) {
      for (double v : {0.21, 0.64}) {
        const SurfaceJet a = s->surface->Jet(u, v, 2), n = numeric.Jet(u, v, 2);
        for (auto [x, y] : {std::pair{a.fu, n.fu}, {a.fv, n.fv}})
          EXPECT_LT(Norm(x - y), 1e-8) << spec;
        for (auto [x, y] : {std::pair{a.fuu, n.fuu}, {a.fuv, n.fuv}, {a.fvv, n.fvv}}) {
          EXPECT_LT(Norm(x - y), 1e-4 * (1 + Norm(x))) << spec;
        }
      }
    }
  }
}

TEST(Surfaces, CurvaturesOfTheSphereAndTorusMatchTheirFormulas) {
  auto sphere = MakeSphere(2);
  const SurfaceGeometry g = GeometryOf(sphere->Jet(0.3, 0.4, 2));
  EXPECT_NEAR(g.gaussian_curvature, 0.25, 1e-12);
  EXPECT_NEAR(std::fabs(g.mean_curvature), 0.5, 1e-12);
  // Torus: K = cos b / (r (R + r cos b)).
  const double big_r = 1, r = 0.4, v = 0.1, b = 2 * M_PI * v;
  auto torus = MakeTorus(big_r, r);
  EXPECT_NEAR(GeometryOf(torus->Jet(0.7, v, 2)).gaussian_curvature,
              std::cos(b) / (r * (big_r + r * std::cos(b))), 1e-10);
}

// The client routes by the tree key of the specs as written (no catalogue in
// the client): that is the server's own tree key when they are canonical, and
// whitespace does not change it.
TEST(Engine, TheRoutingKeyOfCanonicalSpecsIsTheTreeKey) {
  DirectTreeSource source;
  SamplingEngine engine(RegisteredSurfaceKinds(), {}, &source);
  for (const char* surface : {"torus:R=2;r=0.5", "superellipsoid:e=1/3", "expr:x=u;y=v;z=u*v"}) {
    TreeSpec spec;
    spec.surface = surface;
    spec.density = "gaussian:floor=0.1";
    spec.options.curve = CurveType::kPeano;
    auto prepared = engine.Prepare(spec, 1000);
    ASSERT_TRUE(prepared.ok()) << prepared.status();
    TreeSpec canonical = spec;
    canonical.surface = MakeSurface(spec.surface)->canonical;
    canonical.density = MakeDensity(spec.density)->canonical;
    EXPECT_EQ(RoutingKey(canonical), prepared->key.Hex()) << surface;
    TreeSpec spaced = canonical;
    spaced.surface = " " + canonical.surface + " ";
    spaced.surface.insert(spaced.surface.find(':') + 1, "  ");
    EXPECT_EQ(RoutingKey(spaced), RoutingKey(canonical)) << surface;
    spaced.options.curve = CurveType::kHilbert;  // another tree, another key
    EXPECT_NE(RoutingKey(spaced), RoutingKey(canonical)) << surface;
  }
}

}  // namespace
}  // namespace sfc
