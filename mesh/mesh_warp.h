// Hierarchical sample warping on a triangle mesh (docs/ALGORITHM.md, "Sobol
// sets"): the mesh's counterpart of core/tree_warp.h, a measure-preserving
// map from the unit square onto the mesh with the tree's mass as its measure
// (McCool and Harwood 1997; Clarberg et al. 2005, Sect. 4).
//
// The square is halved at 1/2, the first coordinate at even depths and the
// second at odd ones, and the mass along the curve with it: a node is the
// mass interval [k, k + 1) 2^-depth of the whole. Each line is a line of the
// net's elementary intervals, so every aligned block of 2^m points fills
// both sides exactly, whatever the integrand does across the line (mass-
// proportional lines between whole leaves, which the mesh's irregular
// triangle areas make, let a point cross each one at random and cost as much
// as a jittered set; docs/QUALITY.md, "Integration"). The halving stops at
// the first node inside one leaf; one still across leaves 12 levels
// below the leaf level is split by mass. Inside the leaf the node's share of
// the leaf cell's mass goes to one of the cell's halves (E, A, M), (A, X, M)
// by their masses and grows there from the outer corner (E, resp. X) in
// similar triangles: the next coordinate to be halved gives the share, the
// other the place along the scaled triangle's far side (exactly by the
// cell's linear density model). Both halves place that side, A M, alike, so
// the map is continuous, and a share near either end of the leaf is a small
// triangle at E or X.
//
// The point is recorded by its address: its leaf and the bisection choices
// below the leaf that hold it (MeshCurveTree::PathOf), which sort a set into
// curve order and place it (MeshCurveTree::DescendPaths).
//
// Thread-safety: immutable after construction; thread-safe.
#ifndef SFCSAMPLER_MESH_MESH_WARP_H_
#define SFCSAMPLER_MESH_MESH_WARP_H_

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/curve_samples.h"
#include "core/vector_math.h"
#include "mesh/mesh_curve_tree.h"

namespace sfc {

class MeshWarp {
 public:
  // O(leaves) time and at most 32 bytes a leaf (and 8 MB). REQUIRES: `tree`
  // outlives the warp.
  explicit MeshWarp(const MeshCurveTree& tree);

  // The address of the image of (a, b) in [0, 1]^2 (clamped); index 0.
  CurveAddress Locate(double a, double b) const {
    CurveAddress at;
    LocateMany(1, &a, &b, &at);
    return at;
  }
  // out[i] = Locate(a[i], b[i]) for i < n, bit for bit on every vector path
  // (REQUIRES: math::Runs(path)): the leaf searches, the placement in
  // uniform cells and the bisections below the leaves (PathsOf) run over the
  // batch 8 lanes at a time on AVX-512F, 4 on AVX2 (integer lanes and
  // gathers) and on AVX, 2 on the baseline's SSE2
  // (mesh/mesh_warp_lanes.h); kScalar is the reference, one point at a time.
  void LocateMany(size_t n, const double* a, const double* b, CurveAddress* out,
                  math::VectorPath path = math::BestVectorPath()) const;

  // paths[i] = MeshCurveTree::PathOf(pa[i], pb[i]) for i < n, bit for bit,
  // on the vector path `path` (lanes of the same IEEE operations; AVX-512F,
  // AVX2, AVX or the baseline's). REQUIRES: math::Runs(path).
  static void PathsOf(size_t n, const double* pa, const double* pb, uint64_t* paths,
                      math::VectorPath path = math::BestVectorPath());

 private:
  // The leaf holding the image of (a, b) and the point's place in the
  // leaf's frame (E (0, 0), X (1, 0), A (0, 1)).
  void LocateInLeaf(double a, double b, size_t* leaf, double* pa, double* pb) const;
  // Its first part: the leaf, the share f in [0, 1] of the leaf's mass and
  // g in [0, 1) across it that PlaceInCell (mesh_warp.cc) turns into the place.
  void LeafShare(double a, double b, size_t* leaf, double* f, double* g) const;

  const MeshCurveTree& tree_;
  int max_depth_ = 0;             // halvings before a node across leaves is split by mass
  bool uniform_density_ = false;  // every leaf cell's model is uniform
  // Node j of depth bucket_bits_ meets leaves bucket_leaves_[2j] ..
  // bucket_leaves_[2j + 1]: where the search for a node's leaves starts.
  int bucket_bits_ = 0;
  std::vector<uint32_t> bucket_leaves_;
};

}  // namespace sfc

#endif  // SFCSAMPLER_MESH_MESH_WARP_H_
