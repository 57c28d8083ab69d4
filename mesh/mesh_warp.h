// Hierarchical sample warping on a triangle mesh (docs/ALGORITHM.md, "Sobol
// sets"): the mesh's counterpart of core/tree_warp.h, a measure-preserving
// map from the unit square onto the mesh with the tree's mass as its measure
// (McCool and Harwood 1997; Clarberg et al. 2005, Sect. 4).
//
// A balanced binary tree over the leaves in curve order (each node split
// where its mass halves, as nearly as leaves allow) splits the point's first
// coordinate at even depths and its second at odd ones, by the two halves'
// masses, rescaling the coordinate each time. Inside a leaf cell the split
// goes on down the cell's own bisection (mesh/mesh_curve_tree.h) by the exact
// integrals of its linear density model while that model still varies
// across the cell, alternating as before; then the area-preserving map of
// the square onto the cell's triangle, (1 - sqrt a) E + sqrt a (1 - b) X +
// sqrt a b A (Turk 1990), places the point.
//
// The point is recorded by its address: its leaf and the 52 bisection
// choices below the leaf that hold it, the same digits by which
// MeshCurveTree::Descend places a uniform cell's samples, so addresses sort a
// set into curve order and place it.
//
// Thread-safety: immutable after construction; thread-safe.
#ifndef SFCSAMPLER_MESH_MESH_WARP_H_
#define SFCSAMPLER_MESH_MESH_WARP_H_

#include <array>
#include <cstdint>
#include <vector>

#include "core/curve_samples.h"
#include "mesh/mesh_curve_tree.h"

namespace sfc {

class MeshWarp {
 public:
  // O(leaves log leaves). REQUIRES: `tree` outlives the warp.
  explicit MeshWarp(const MeshCurveTree& tree);

  // The address of the image of (a, b) in [0, 1]^2 (clamped); index 0.
  CurveAddress Locate(double a, double b) const;

  // The sample at `at`: barycentric coordinates in the leaf's triangle (the
  // centre of the addressed sub-cell) and its area position along the
  // triangle's curve, as MeshCurveTree::Descend gives them.
  void Place(const CurveAddress& at, MeshCurveTree::Cell* cell, std::array<double, 3>* bary,
             double* area_position) const;

 private:
  struct Node {
    int32_t child[2];   // node index, or -(leaf + 1)
    double split;       // the first half's share of the node's mass
    double inverse[2];  // each half's share, inverted (0 for none)
  };
  int32_t Build(size_t lo, size_t hi);

  const MeshCurveTree& tree_;
  std::vector<Node> nodes_;
  int32_t root_ = 0;
};

}  // namespace sfc

#endif  // SFCSAMPLER_MESH_MESH_WARP_H_
