// The mesh warp's batches (mesh/mesh_warp.h) give the scalar code's bits:
// MeshWarp::PathsOf equals MeshCurveTree::PathOf, and MeshWarp::LocateMany
// its scalar path (one point at a time), on every vector path this CPU runs,
// over random points, edges, corners and dyadic lines.
#include "mesh/mesh_warp.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>
#include <random>
#include <vector>

#include "core/vector_math.h"
#include "gtest/gtest.h"
#include "mesh/icosphere.h"
#include "mesh/mesh_curve_tree.h"
#include "mesh/mesh_density.h"
#include "mesh/mesh_surface.h"

namespace sfc {
namespace {

TEST(MeshWarp, PathsOfIsPathOfOnEveryVectorPath) {
  std::mt19937_64 rng(36);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<double> pa, pb;
  for (int i = 0; i < 4099; ++i) {  // not a multiple of a block: the padded tail too
    double a = unit(rng), b = unit(rng);
    if (a + b > 1) a = 1 - a, b = 1 - b;  // inside the frame's triangle
    pa.push_back(a), pb.push_back(b);
  }
  // Corners, edges and the halving lines, where the branches meet.
  for (double a : {0.0, 0.25, 0.5, 1.0}) {
    for (double b : {0.0, 0.5, 1.0 - a}) pa.push_back(a), pb.push_back(b);
  }
  // Points a rounding off the triangle's edges and the line 2a + b = 1 (the
  // first level's clamps act; the later levels skip two of them, which must
  // never have acted), points of every scale down to 2^-60, and points
  // outside the triangle and the square, both zeros among them.
  for (int i = 0; i < 4000; ++i) {
    const double a = unit(rng), scale = std::ldexp(1.0, -static_cast<int>(rng() % 61));
    const int ulps = static_cast<int>(rng() % 7) - 3;
    double b = i % 2 == 0 ? 1 - a : 1 - 2 * a;
    for (int k = 0; k < std::abs(ulps); ++k) b = std::nextafter(b, ulps > 0 ? 2.0 : -2.0);
    pa.push_back(a * scale), pb.push_back(i % 3 == 0 ? b : b * scale);
    pa.push_back(unit(rng) * scale), pb.push_back(unit(rng) * scale);
  }
  for (double a : {-0.0, -0.25, 1.0 + 0x1.0p-52, 1.5, 0x1.0p-1074}) {
    for (double b : {-0.0, -0.5, 0.0, 1.0, 1.25, 0x1.0p-1074}) pa.push_back(a), pb.push_back(b);
  }
  std::vector<uint64_t> expected(pa.size());
  for (size_t i = 0; i < pa.size(); ++i) expected[i] = MeshCurveTree::PathOf(pa[i], pb[i]);
  for (math::VectorPath path : math::kVectorPaths) {
    if (!math::Runs(path)) continue;
    for (size_t n : {size_t{1}, size_t{31}, pa.size()}) {
      std::vector<uint64_t> got(n);
      MeshWarp::PathsOf(n, pa.data(), pb.data(), got.data(), path);
      for (size_t i = 0; i < n; ++i) {
        ASSERT_EQ(got[i], expected[i]) << math::VectorPathName(path) << " point " << i;
      }
    }
  }
}

// Uniform (no cell decoded), a linear density (the scalar placement after the
// batch's search) and one that is zero on half the sphere (leaves of no mass).
TEST(MeshWarp, LocateManyIsTheScalarLocateOnEveryVectorPath) {
  const auto surface = MeshSurface::Create(MakeIcosphere(3), false);
  const std::shared_ptr<const MeshDensity> densities[] = {
      UniformMeshDensity(),
      std::make_shared<FunctionMeshDensity>(
          [](const MeshPoint& p) { return 1.5 + p.position.x + 0.3 * p.position.z; }, "linear"),
      std::make_shared<FunctionMeshDensity>(
          [](const MeshPoint& p) { return std::max(0.0, p.position.z); }, "upper half")};
  std::mt19937_64 rng(36);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<double> a, b;
  for (int i = 0; i < 5003; ++i) a.push_back(unit(rng)), b.push_back(unit(rng));
  // Corners, edges, dyadic lines (where nodes and truncations meet), both
  // zeros and the clamps' ends.
  const double below_one = 1.0 - 0x1.0p-53;
  for (double x : {0.0, -0.0, 0x1.0p-40, 0.25, 0.5, 0.75, below_one, 1.0, -1.0, 2.0}) {
    for (double y : {0.0, -0.0, 0.5, 0.375, below_one, 1.0}) a.push_back(x), b.push_back(y);
  }
  for (const auto& density : densities) {
    MeshTreeOptions options;
    options.count = 1 << 16;
    const auto tree = MeshCurveTree::Build(surface, density, options);
    ASSERT_TRUE(tree.ok()) << tree.status();
    const MeshWarp warp(**tree);
    std::vector<CurveAddress> expected(a.size());
    warp.LocateMany(a.size(), a.data(), b.data(), expected.data(), math::VectorPath::kScalar);
    for (math::VectorPath path : math::kVectorPaths) {
      if (!math::Runs(path)) continue;
      for (size_t n : {size_t{1}, size_t{13}, size_t{64}, a.size()}) {
        std::vector<CurveAddress> got(n);
        warp.LocateMany(n, a.data(), b.data(), got.data(), path);
        for (size_t i = 0; i < n; ++i) {
          ASSERT_EQ(got[i].leaf, expected[i].leaf)
              << density->spec() << " " << math::VectorPathName(path) << " point " << i;
          ASSERT_EQ(got[i].digits, expected[i].digits)
              << density->spec() << " " << math::VectorPathName(path) << " point " << i;
          ASSERT_EQ(got[i].index, expected[i].index);
        }
      }
    }
    // Locate is the batch's answer for one point.
    const CurveAddress one = warp.Locate(a[7], b[7]);
    EXPECT_EQ(one.leaf, expected[7].leaf);
    EXPECT_EQ(one.digits, expected[7].digits);
  }
}

}  // namespace
}  // namespace sfc
