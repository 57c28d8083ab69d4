// The mesh warp's batches (mesh/mesh_warp.h) give the scalar code's bits:
// MeshWarp::PathsOf equals MeshCurveTree::PathOf on every vector path this
// CPU runs, over random points of the leaf frame, its edges and corners.
#include "mesh/mesh_warp.h"

#include <cstdint>
#include <random>
#include <vector>

#include "core/vector_math.h"
#include "gtest/gtest.h"
#include "mesh/mesh_curve_tree.h"

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
  std::vector<uint64_t> expected(pa.size());
  for (size_t i = 0; i < pa.size(); ++i) expected[i] = MeshCurveTree::PathOf(pa[i], pb[i]);
  for (math::VectorPath path : {math::VectorPath::kScalar, math::VectorPath::kSse2,
                                math::VectorPath::kAvx, math::VectorPath::kAvx512}) {
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

}  // namespace
}  // namespace sfc
