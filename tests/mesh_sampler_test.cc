// Sampling triangle meshes: the curve, the masses, the cursor. Properties:
// low cap discrepancy on the icosphere (far below i.i.d. points), counts per
// triangle group within the jittering bound of area x density, determinism,
// ranges joining to the full set, regions equal to the filtered full set,
// locality along the curve, a tree sized by the mesh (not by N), discrete
// curvature against the sphere's.
#include <algorithm>
#include <cstdio>
#include <cmath>
#include <map>
#include <random>
#include <set>
#include <tuple>

#include "gtest/gtest.h"
#include "mesh/curvature.h"
#include "mesh/icosphere.h"
#include "mesh/iid_points.h"
#include "mesh/mesh_curve_tree.h"
#include "mesh/mesh_sampler.h"

namespace sfc {
namespace {

std::shared_ptr<const MeshSurface> Icosphere(int s, bool curvature = false) {
  static std::map<std::pair<int, bool>, std::shared_ptr<const MeshSurface>> cache;
  auto& entry = cache[{s, curvature}];
  if (!entry) entry = MeshSurface::Create(MakeIcosphere(s), curvature);
  return entry;
}

std::shared_ptr<const MeshSampler> MakeSampler(std::shared_ptr<const MeshSurface> surface,
                                                std::shared_ptr<const MeshDensity> density,
                                                uint64_t n, uint64_t seed = 7,
                                                SequenceKind kind = SequenceKind::kJittered) {
  MeshTreeOptions options;
  options.count = n;
  auto tree = MeshCurveTree::Build(std::move(surface), std::move(density), options);
  EXPECT_TRUE(tree.ok()) << tree.status();
  return std::make_shared<MeshSampler>(*tree, Sequence(kind, n, seed));
}

// The mesh columns of a draw: the batch's triangle column, and corner 0's
// barycentric coordinate from the sample computed alone (MeshSampler::At).
struct MeshColumns {
  std::vector<uint32_t> triangle;
  std::vector<double> w;
};

struct Drawn {
  SampleBatch batch;
  MeshColumns mesh;
};

Drawn Draw(const std::shared_ptr<const MeshSampler>& sampler, uint64_t begin, uint64_t end,
           const Region& region = {}, SampleFields fields = {}) {
  fields.triangle = true;
  auto cursor = SampleCursor::Create(sampler, begin, end, region, fields);
  EXPECT_TRUE(cursor.ok()) << cursor.status();
  Drawn out;
  while (true) {
    auto n = (*cursor)->Next(1000, &out.batch);
    EXPECT_TRUE(n.ok()) << n.status();
    if (!n.ok() || *n == 0) break;
  }
  out.mesh.triangle = out.batch.triangle;
  for (uint64_t k : out.batch.index) out.mesh.w.push_back(sampler->At(k).bary[0]);
  return out;
}

Vec3 At(const SampleBatch& b, size_t i) { return {b.x[i], b.y[i], b.z[i]}; }

TEST(MeshCurvature, SphereHasUnitCurvatureAndGaussBonnetHolds) {
  const TriangleMesh sphere = MakeIcosphere(4);
  const VertexCurvature c = ComputeVertexCurvature(sphere);
  double total_k = 0, area = 0;
  for (size_t i = 0; i < sphere.positions.size(); ++i) {
    EXPECT_NEAR(c.gaussian[i], 1.0, 0.03) << i;
    EXPECT_NEAR(c.mean[i], 1.0, 0.03) << i;
    total_k += c.gaussian[i] * c.mixed_area[i];
    area += c.mixed_area[i];
  }
  EXPECT_NEAR(total_k, 4 * M_PI, 1e-9);  // sum of angle deficits = 2 pi chi exactly
  EXPECT_NEAR(area, sphere.stats.area, 1e-9);  // mixed areas tile the surface
}

// Largest |count - expected| over random spherical caps {p : <p/|p|, c> >= h}.
double CapDiscrepancy(const std::vector<Vec3>& points, int caps, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> uniform(-1, 1);
  double worst = 0;
  for (int c = 0; c < caps; ++c) {
    Vec3 axis{normal(rng), normal(rng), normal(rng)};
    axis = axis * (1 / Norm(axis));
    const double h = uniform(rng);
    size_t inside = 0;
    for (const Vec3& p : points) inside += Dot(p, axis) >= h * Norm(p);
    const double expected = points.size() * (1 - h) / 2;  // cap area / sphere area
    worst = std::max(worst, std::abs(inside - expected));
  }
  return worst;
}

TEST(MeshSampler, IcosphereCapDiscrepancyIsFarBelowIid) {
  const auto surface = Icosphere(6);
  for (uint64_t n : {1024u, 8192u}) {
    const Drawn d = Draw(MakeSampler(surface, UniformMeshDensity(), n), 0, n);
    ASSERT_EQ(d.batch.size(), n);
    std::vector<Vec3> ours;
    for (size_t i = 0; i < n; ++i) ours.push_back(At(d.batch, i));
    const double ours_d = CapDiscrepancy(ours, 300, 11);
    // The typical i.i.d. figure: the median of three sets.
    std::vector<double> iid;
    for (uint64_t s = 1; s <= 3; ++s)
      iid.push_back(CapDiscrepancy(IidMeshPoints(surface->mesh(), n, s), 300, 11));
    std::sort(iid.begin(), iid.end());
    const double iid_d = iid[1];
    SCOPED_TRACE(::testing::Message() << "N=" << n << " ours=" << ours_d << " iid=" << iid_d);
    EXPECT_LT(ours_d, (n < 4096 ? 0.5 : 0.3) * iid_d);
    std::printf("N=%d cap discrepancy (count): ours %.2f, i.i.d. %.2f\n", static_cast<int>(n),
                ours_d, iid_d);
    EXPECT_LT(ours_d, 3 * std::pow(n, 0.25));  // the jittered set's own scale, N^(1/4)
  }
}

// Counts per group of triangles (octants of the centroid) against
// N * (group mass / total mass), computed here from exact triangle areas and
// linear weights, independent of the tree: within 2 per run of the group
// along the curve (one jittered sample per stratum of 1/N).
void CheckGroupCounts(const std::shared_ptr<const MeshSampler>& sampler, uint64_t n,
                      bool weighted) {
  const MeshCurveTree& tree = sampler->tree();
  const TriangleMesh& mesh = tree.surface().mesh();
  auto group_of = [&](uint32_t t) {
    const auto& f = mesh.triangles[t];
    const Vec3 c = mesh.positions[f[0]] + mesh.positions[f[1]] + mesh.positions[f[2]];
    return (c.x > 0) + 2 * (c.y > 0) + 4 * (c.z > 0);
  };
  std::vector<double> mass(8, 0);
  std::vector<int> runs(8, 0);
  double total = 0;
  int previous = -1;
  for (size_t r = 0; r < tree.triangle_count(); ++r) {
    const uint32_t t = tree.triangle_at_rank(r);
    const auto& f = mesh.triangles[t];
    double m = 0.5 * Norm(mesh.FaceCross(t));
    if (weighted) m *= (mesh.weights[f[0]] + mesh.weights[f[1]] + mesh.weights[f[2]]) / 3;
    const int g = group_of(t);
    mass[g] += m;
    total += m;
    if (g != previous) ++runs[g];
    previous = g;
  }
  const Drawn d = Draw(sampler, 0, n);
  std::vector<double> count(8, 0);
  for (size_t i = 0; i < d.batch.size(); ++i) ++count[group_of(d.mesh.triangle[i])];
  for (int g = 0; g < 8; ++g) {
    EXPECT_LE(std::abs(count[g] - n * mass[g] / total), 2.0 * runs[g] + 1e-6)
        << "group " << g << " runs " << runs[g];
  }
}

TEST(MeshSampler, TriangleGroupCountsMatchAreaTimesDensity) {
  CheckGroupCounts(MakeSampler(Icosphere(4), UniformMeshDensity(), 50000), 50000, false);
  TriangleMesh weighted = MakeIcosphere(4);
  weighted.weights.resize(weighted.positions.size());
  for (size_t i = 0; i < weighted.weights.size(); ++i) {
    weighted.weights[i] = 0.2 + weighted.positions[i].z * weighted.positions[i].z;
  }
  CheckGroupCounts(MakeSampler(MeshSurface::Create(weighted, false), VertexWeightMeshDensity(),
                               50000),
                   50000, true);
}

TEST(MeshSampler, DeterministicAndEqualToRandomAccess) {
  const uint64_t n = 20000;
  SampleFields all{.normal = true, .density = true, .curve_position = true};
  const auto density = GaussianCurvatureMeshDensity(0.1);
  const Drawn a = Draw(MakeSampler(Icosphere(4, true), density, n, 5), 0, n, {}, all);
  const Drawn b = Draw(MakeSampler(MeshSurface::Create(MakeIcosphere(4), true), density, n, 5), 0,
                       n, {}, all);
  ASSERT_EQ(a.batch.size(), n);
  EXPECT_EQ(a.batch.x, b.batch.x);
  EXPECT_EQ(a.batch.u, b.batch.u);
  EXPECT_EQ(a.batch.nz, b.batch.nz);
  EXPECT_EQ(a.batch.density, b.batch.density);
  EXPECT_EQ(a.mesh.triangle, b.mesh.triangle);
  const auto sampler = MakeSampler(Icosphere(4, true), density, n, 5);
  for (uint64_t k : {0ul, 1ul, 777ul, n - 1}) {
    const MeshSample s = sampler->At(k);
    EXPECT_EQ(s.position.x, a.batch.x[k]);
    EXPECT_EQ(s.triangle, a.mesh.triangle[k]);
  }
  // Columns are consistent: barycentrics sum to 1, the point is on its
  // triangle, curve positions increase, normals are unit.
  const TriangleMesh& mesh = sampler->tree().surface().mesh();
  for (size_t i = 0; i < n; ++i) {
    const double w = a.mesh.w[i], u = a.batch.u[i], v = a.batch.v[i];
    ASSERT_NEAR(u + v + w, 1, 1e-12);
    ASSERT_TRUE(u > 0 && v > 0 && w > 0);
    const auto& f = mesh.triangles[a.mesh.triangle[i]];
    const Vec3 p = mesh.positions[f[0]] * w + mesh.positions[f[1]] * u + mesh.positions[f[2]] * v;
    ASSERT_NEAR(Norm(p - At(a.batch, i)), 0, 1e-12);
    ASSERT_NEAR(Norm(Vec3{a.batch.nx[i], a.batch.ny[i], a.batch.nz[i]}), 1, 1e-12);
    if (i > 0) ASSERT_GT(a.batch.curve_position[i], a.batch.curve_position[i - 1]);
  }
}

// The batch path descends samples together (MeshCurveTree::DescendMany,
// packed two lanes at a time); random access descends one (Descend). Every
// sample must agree to the bit, for uniform cells and model-following ones.
TEST(MeshSampler, EverySampleOfABatchEqualsItsRandomAccess) {
  const uint64_t n = 30000;
  for (const auto& density : {UniformMeshDensity(), GaussianCurvatureMeshDensity(0.1)}) {
    const auto sampler = MakeSampler(Icosphere(3, true), density, n, 11);
    const Drawn a = Draw(sampler, 0, n);
    ASSERT_EQ(a.batch.size(), n);
    for (uint64_t k = 0; k < n; ++k) {
      const MeshSample s = sampler->At(k);
      ASSERT_EQ(s.position.x, a.batch.x[k]) << k;
      ASSERT_EQ(s.position.y, a.batch.y[k]) << k;
      ASSERT_EQ(s.position.z, a.batch.z[k]) << k;
      ASSERT_EQ(s.triangle, a.mesh.triangle[k]) << k;
    }
  }
}

TEST(MeshSampler, RangesJoinToTheFullSetAndHaveNoDuplicates) {
  const uint64_t n = 30000;
  const auto sampler = MakeSampler(Icosphere(5), UniformMeshDensity(), n);
  const Drawn full = Draw(sampler, 0, n);
  SampleBatch joined;
  const uint64_t cuts[] = {0, 1, 4999, 17000, 29999, n};
  for (size_t i = 0; i + 1 < std::size(cuts); ++i)
    joined.Append(Draw(sampler, cuts[i], cuts[i + 1]).batch);
  EXPECT_EQ(joined.index, full.batch.index);
  EXPECT_EQ(joined.x, full.batch.x);
  EXPECT_EQ(joined.z, full.batch.z);
  for (uint64_t k : {0ul, 12345ul, n - 1}) {  // the batched descent equals the single one
    const MeshSample s = sampler->At(k);
    EXPECT_EQ(s.position.x, full.batch.x[k]);
    EXPECT_EQ(s.bary[1], full.batch.u[k]);
  }
  std::set<std::tuple<double, double, double>> distinct;
  for (size_t i = 0; i < n; ++i)
    distinct.insert({full.batch.x[i], full.batch.y[i], full.batch.z[i]});
  EXPECT_EQ(distinct.size(), n);
}

TEST(MeshSampler, RegionEqualsFilteredFullSet) {
  const uint64_t n = 40000;
  for (SequenceKind kind : {SequenceKind::kJittered, SequenceKind::kProgressive}) {
    const auto sampler = MakeSampler(Icosphere(5, true), MeanCurvatureMeshDensity(0.5), n, 3, kind);
    const Region box = Region::Box({-0.3, 0.1, -1.5}, {0.8, 1.5, 0.2});
    const Drawn full = Draw(sampler, 1000, n - 500);
    const Drawn part = Draw(sampler, 1000, n - 500, box);
    SampleBatch filtered;
    for (size_t i = 0; i < full.batch.size(); ++i) {
      if (box.Contains(0, 0, At(full.batch, i))) filtered.AppendFrom(full.batch, i, i + 1);
    }
    ASSERT_GT(filtered.size(), 1000u);
    EXPECT_EQ(part.batch.index, filtered.index);
    EXPECT_EQ(part.batch.y, filtered.y);
  }
  auto rect = SampleCursor::Create(MakeSampler(Icosphere(2), UniformMeshDensity(), 10), 0, 10,
                                       Region::ParameterRect(0, 0.5, 0, 0.5), {});
  EXPECT_EQ(rect.status().code(), absl::StatusCode::kInvalidArgument);
}

TEST(MeshSampler, NonMonotoneSequencesComeInCurveOrder) {
  const uint64_t n = 4096;
  for (SequenceKind kind :
       {SequenceKind::kRandom, SequenceKind::kVanDerCorput, SequenceKind::kProgressive}) {
    const auto sampler = MakeSampler(Icosphere(4), UniformMeshDensity(), n, 9, kind);
    const Drawn d = Draw(sampler, 0, n, {}, {.curve_position = true});
    ASSERT_EQ(d.batch.size(), n);
    std::vector<uint64_t> sorted = d.batch.index;
    std::sort(sorted.begin(), sorted.end());
    for (uint64_t k = 0; k < n; ++k) ASSERT_EQ(sorted[k], k);
    for (size_t i = 1; i < n; ++i)
      ASSERT_GE(d.batch.curve_position[i], d.batch.curve_position[i - 1]);
  }
}

TEST(MeshSampler, ConsecutiveSamplesAreCloseOnTheSurface) {
  const uint64_t n = 50000;
  const Drawn d = Draw(MakeSampler(Icosphere(6), UniformMeshDensity(), n), 0, n);
  std::vector<double> steps;
  for (size_t i = 1; i < n; ++i) steps.push_back(Norm(At(d.batch, i) - At(d.batch, i - 1)));
  std::sort(steps.begin(), steps.end());
  const double spacing = std::sqrt(4 * M_PI / n);  // side of a sample's share of the area
  std::printf(
      "consecutive steps / spacing: median %.2f, p90 %.2f, p99 %.2f, p99.9 %.2f, max %.2f\n",
      steps[n / 2] / spacing, steps[n * 9 / 10] / spacing, steps[n * 99 / 100] / spacing,
      steps[n * 999 / 1000] / spacing, steps.back() / spacing);
  // Most steps are one sample spacing; the 3D Hilbert order of triangles
  // jumps where the curve leaves the shell and re-enters it elsewhere, rarely.
  EXPECT_LT(steps[n / 2], 1.5 * spacing);
  EXPECT_LT(steps[n * 9 / 10], 3 * spacing);
  EXPECT_LT(steps[n * 99 / 100], 10 * spacing);
  // i.i.d. order would put the median step near the sphere's mean chord (4/3).
  EXPECT_LT(steps[n / 2], 0.05);
}

TEST(MeshCurveTree, UniformTreeIsTheMeshWhateverN) {
  const auto surface = Icosphere(6);
  for (uint64_t n : {1000u, 1000000u, 100000000u}) {
    MeshTreeOptions options;
    options.count = n;
    auto tree = MeshCurveTree::Build(surface, UniformMeshDensity(), options);
    ASSERT_TRUE(tree.ok()) << tree.status();
    EXPECT_EQ((*tree)->leaf_count(), surface->triangle_count());
    EXPECT_EQ((*tree)->stats().split_triangles, 0u);
    EXPECT_NEAR((*tree)->total_mass(), surface->mesh().stats.area, 1e-9);
  }
}

TEST(MeshCurveTree, SplitsLargeTrianglesNotTinyOnesAndGrowsSlowerThanN) {
  // One big triangle and a cluster of tiny ones, with a density that varies.
  TriangleMesh mesh;
  mesh.name = "mixed";
  mesh.positions = {{0, 0, 0}, {4, 0, 0}, {0, 4, 0}};
  for (int i = 0; i < 50; ++i) {
    const uint32_t b = mesh.positions.size();
    const double x = 5 + 0.01 * i;
    mesh.positions.insert(mesh.positions.end(), {{x, 0, 0}, {x + 0.01, 0, 0}, {x, 0.01, 0}});
    mesh.triangles.push_back({b, b + 1, b + 2});
  }
  mesh.triangles.push_back({0, 1, 2});
  ASSERT_TRUE(FinalizeMesh(&mesh).ok());
  const auto surface = MeshSurface::Create(mesh, false);
  const auto density = std::make_shared<FunctionMeshDensity>(
      [](const MeshPoint& p) { return std::exp(std::sin(2 * p.position.x) + p.position.y); },
      "exp(sin(2x)+y)");
  std::vector<size_t> leaves;
  for (uint64_t n : {uint64_t{1} << 12, uint64_t{1} << 20}) {
    MeshTreeOptions options;
    options.count = n;
    auto tree = MeshCurveTree::Build(surface, density, options);
    ASSERT_TRUE(tree.ok()) << tree.status();
    const MeshCurveTree& t = **tree;
    size_t big = 0, tiny_max = 0;
    for (size_t r = 0; r < t.triangle_count(); ++r) {
      const size_t count = t.first_leaf(r + 1) - t.first_leaf(r);
      if (t.triangle_at_rank(r) == 50) big = count;
      else tiny_max = std::max(tiny_max, count);
    }
    EXPECT_GT(big, 16u) << n;
    if (n == (uint64_t{1} << 12)) EXPECT_EQ(tiny_max, 1u);
    EXPECT_EQ(t.stats().capped_leaves, 0u);
    EXPECT_LT(t.leaf_count(), n / 8);
    leaves.push_back(t.leaf_count());
    std::printf("N=%llu: %zu leaves, big triangle %zu, tiny triangles at most %zu\n",
                static_cast<unsigned long long>(n), t.leaf_count(), big, tiny_max);
  }
  // 256x the samples: N^(3/4) would be 64x the leaves; well under 256x.
  EXPECT_LT(leaves[1], 100 * leaves[0]);
}

TEST(MeshCurveTree, BadDensitiesAreErrors) {
  auto negative = std::make_shared<FunctionMeshDensity>(
      [](const MeshPoint& p) { return p.position.z; }, "z");
  auto r1 = MeshCurveTree::Build(Icosphere(2), negative, {});
  EXPECT_EQ(r1.status().code(), absl::StatusCode::kInvalidArgument);
  auto zero = std::make_shared<FunctionMeshDensity>([](const MeshPoint&) { return 0.0; }, "0");
  // INVALID_ARGUMENT, as a formula surface's density that integrates to zero.
  EXPECT_EQ(MeshCurveTree::Build(Icosphere(2), zero, {}).status().code(),
            absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(MeshCurveTree::Build(Icosphere(2), VertexWeightMeshDensity(), {}).status().code(),
            absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(MeshCurveTree::Build(Icosphere(2), GaussianCurvatureMeshDensity(0), {}).status().code(),
            absl::StatusCode::kInvalidArgument);
  // Too small to resolve (its leaves' masses subnormal, samples coinciding):
  // refused with what to do; a small one that resolves is built.
  auto tiny = std::make_shared<FunctionMeshDensity>([](const MeshPoint&) { return 1e-320; }, "t");
  const auto r2 = MeshCurveTree::Build(Icosphere(2), tiny, {});
  EXPECT_EQ(r2.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(r2.status().message().find("scale it up"), std::string::npos) << r2.status();
  auto small = std::make_shared<FunctionMeshDensity>([](const MeshPoint&) { return 1e-280; }, "s");
  EXPECT_TRUE(MeshCurveTree::Build(Icosphere(2), small, {}).ok());
}

// The sobol sequence warped onto a mesh (mesh/mesh_warp.h): exact N, every
// index once, curve order, shards that concatenate to the whole set, and
// means of a quadratic that meet its exact integral over the flat triangles
// (edge-midpoint rule) well inside i.i.d. points' error (about 5e-3 here). On
// a mesh of many triangles the warp's error is about the jittered set's
// (docs/QUALITY.md, "Integration"), not the fifth the issue asks.
TEST(MeshSampler, SobolSetsAreExactOrderedAndIntegrateQuadratics) {
  const auto surface = Icosphere(3);
  const TriangleMesh& mesh = surface->mesh();
  auto f = [](const Vec3& p) { return p.x * p.x + 0.3 * p.y * p.z + p.z; };
  double area = 0, integral = 0;
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& tri = mesh.triangles[t];
    const Vec3 a = mesh.positions[tri[0]], b = mesh.positions[tri[1]], c = mesh.positions[tri[2]];
    const double at = Norm(mesh.FaceCross(t)) / 2;
    area += at;
    integral += at / 3 * (f((a + b) * 0.5) + f((b + c) * 0.5) + f((c + a) * 0.5));
  }
  const double exact = integral / area;
  const uint64_t n = 1 << 14;
  double sobol_error = 0, jittered_error = 0;
  for (uint64_t seed : {1, 2, 3}) {
    const auto sampler = MakeSampler(surface, UniformMeshDensity(), n, seed, SequenceKind::kSobol);
    const Drawn d = Draw(sampler, 0, n, {}, {.curve_position = true});
    ASSERT_EQ(d.batch.size(), n);
    std::vector<uint64_t> sorted = d.batch.index;
    std::sort(sorted.begin(), sorted.end());
    for (uint64_t k = 0; k < n; ++k) ASSERT_EQ(sorted[k], k);
    for (size_t i = 1; i < n; ++i) {
      ASSERT_GE(d.batch.curve_position[i], d.batch.curve_position[i - 1]);
    }
    SampleBatch joined;
    for (uint64_t i = 0; i < 4; ++i) joined.Append(Draw(sampler, i * n / 4, (i + 1) * n / 4).batch);
    EXPECT_EQ(joined.index, d.batch.index);
    EXPECT_EQ(joined.x, d.batch.x);
    EXPECT_EQ(joined.z, d.batch.z);
    double sum = 0;
    for (size_t i = 0; i < n; ++i) sum += f(At(d.batch, i));
    sobol_error += std::fabs(sum / n - exact) / 3;
    const Drawn j = Draw(MakeSampler(surface, UniformMeshDensity(), n, seed), 0, n);
    sum = 0;
    for (size_t i = 0; i < n; ++i) sum += f(At(j.batch, i));
    jittered_error += std::fabs(sum / n - exact) / 3;
  }
  std::printf("mesh mean error at %llu: sobol %.3g, jittered %.3g\n",
              static_cast<unsigned long long>(n), sobol_error, jittered_error);
  EXPECT_LT(sobol_error, 1e-3);
}

// The warp halves the square at 1/2 and the mass along the curve with it
// (mesh/mesh_warp.h): every point of the dyadic box k of depth 6 (the first
// coordinate halved at even depths, the second at odd ones) lands in a leaf
// that meets the mass interval [k, k + 1) / 64 of the whole, on a mesh whose
// triangles' areas are not dyadic, and with a density.
TEST(MeshSampler, SobolWarpSendsDyadicBoxesToEqualMassIntervals) {
  TriangleMesh mesh = MakeIcosphere(2);
  for (const Vec3& p : mesh.positions) mesh.weights.push_back(1.5 + p.x);
  const auto surface = MeshSurface::Create(std::move(mesh), false);
  for (bool weighted : {false, true}) {
    const auto sampler =
        MakeSampler(surface, weighted ? VertexWeightMeshDensity() : UniformMeshDensity(), 4096, 1,
                    SequenceKind::kSobol);
    const MeshCurveTree& tree = sampler->tree();
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> unit(0, 1);
    constexpr int kDepth = 6;
    for (int i = 0; i < 4096; ++i) {
      const double a = unit(rng), b = unit(rng);
      uint64_t k = 0;
      double c[2] = {a, b};
      for (int level = 0; level < kDepth; ++level) {
        double& x = c[level % 2];
        const int bit = x < 0.5 ? 0 : 1;
        x = 2 * x - bit;
        k = 2 * k + bit;
      }
      const CurveAddress at = sampler->warp()->Locate(a, b);
      const double lo = std::ldexp(static_cast<double>(k), -kDepth) * tree.total_mass();
      const double hi = std::ldexp(static_cast<double>(k + 1), -kDepth) * tree.total_mass();
      const double slack = 1e-12 * tree.total_mass();
      ASSERT_LT(tree.mass_begin(at.leaf), hi + slack) << a << " " << b << " box " << k;
      ASSERT_GT(tree.mass_ends()[at.leaf], lo - slack) << a << " " << b << " box " << k;
    }
  }
}

// Weights 1.5 + x at the vertices: the density 1.5 + x on the flat triangles.
// The share of its mass in x > 0, by a fine quadrature of our own (sub-triangle
// centroids, 64 a side), is met within 0.1 % of N (16 samples; i.i.d. points
// would miss it by about 60).
TEST(MeshSampler, SobolSetsKeepTheMassSplit) {
  TriangleMesh mesh = MakeIcosphere(3);
  for (const Vec3& p : mesh.positions) mesh.weights.push_back(1.5 + p.x);
  double right = 0, total = 0;
  constexpr int kSide = 64;
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& tri = mesh.triangles[t];
    const Vec3 a = mesh.positions[tri[0]], b = mesh.positions[tri[1]], c = mesh.positions[tri[2]];
    const double cell = Norm(mesh.FaceCross(t)) / 2 / (kSide * kSide);
    for (int i = 0; i < kSide; ++i) {
      for (int j = 0; i + j < kSide; ++j) {
        // The up and down sub-triangles of row i, column j, by their centroids.
        for (int down = 0; down < (i + j + 1 < kSide ? 2 : 1); ++down) {
          const double s = (i + (down ? 2.0 : 1.0) / 3) / kSide;
          const double r = (j + (down ? 2.0 : 1.0) / 3) / kSide;
          const Vec3 p = a + (b - a) * s + (c - a) * r;
          total += (1.5 + p.x) * cell;
          if (p.x > 0) right += (1.5 + p.x) * cell;
        }
      }
    }
  }
  const auto surface = MeshSurface::Create(std::move(mesh), false);
  const uint64_t n = 1 << 14;
  const auto sampler = MakeSampler(surface, VertexWeightMeshDensity(), n, 4, SequenceKind::kSobol);
  const Drawn d = Draw(sampler, 0, n);
  double count = 0;
  for (size_t i = 0; i < n; ++i) count += d.batch.x[i] > 0;
  EXPECT_NEAR(count, right / total * n, 16);
}

// The cursor's bucket sort (core/sample_cursor.cc) puts a set in the order
// of one comparison sort of its addresses (CurveAddress::Key), with a
// density and without, on an icosphere beside one triangle of most of the
// mass, whose samples overflow the sort's per-thread copy of a coarse bucket
// (2^16 addresses) and are permuted in place instead; for 1 and 2 threads.
TEST(MeshSampler, SobolSetsComeInTheOrderOfOneComparisonSort) {
  TriangleMesh mesh = MakeIcosphere(3);
  const uint32_t v = static_cast<uint32_t>(mesh.positions.size());
  mesh.positions.insert(mesh.positions.end(), {{10, 0, 0}, {90, 0, 0}, {10, 80, 0}});
  mesh.triangles.push_back({v, v + 1, v + 2});
  ASSERT_TRUE(FinalizeMesh(&mesh).ok());
  for (const Vec3& p : mesh.positions) mesh.weights.push_back(1.5 + std::sin(p.x + p.y));
  const auto surface = MeshSurface::Create(std::move(mesh), false);
  const uint64_t n = 200'000;
  for (bool weighted : {false, true}) {
    const auto sampler =
        MakeSampler(surface, weighted ? VertexWeightMeshDensity() : UniformMeshDensity(), n, 3,
                    SequenceKind::kSobol);
    std::vector<CurveAddress> expected(n);
    sampler->AddressesOf(nullptr, 0, n, expected.data());
    std::sort(expected.begin(), expected.end());
    for (int threads : {1, 2}) {
      auto cursor = SampleCursor::Create(sampler, 0, n, {}, {}, threads);
      ASSERT_TRUE(cursor.ok()) << cursor.status();
      SampleBatch batch;
      while (true) {
        auto got = (*cursor)->Next(65536, &batch);
        ASSERT_TRUE(got.ok()) << got.status();
        if (*got == 0) break;
      }
      ASSERT_EQ(batch.size(), n);
      for (uint64_t i = 0; i < n; ++i) {
        ASSERT_EQ(batch.index[i], expected[i].index) << "weighted " << weighted << " at " << i;
      }
    }
  }
}

}  // namespace
}  // namespace sfc
