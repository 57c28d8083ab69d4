// Hierarchical sample warping through a curve tree (docs/ALGORITHM.md,
// "Sobol sets"): a measure-preserving map from the unit square onto the
// surface's parameter square, with the mass of the tree as its measure. It
// carries the points of a scrambled Sobol net (core/sequence.h, kSobol) onto
// the surface so that their low discrepancy in the square becomes low
// discrepancy of area x density (McCool and Harwood 1997, probability trees;
// Clarberg, Jarosz, Akenine-Moeller and Jensen 2005, Sect. 4, hierarchical
// sample warping).
//
// At a node whose cell splits into g x g children (g = 2 for Hilbert, 3 for
// Hilbert II and Peano), the point's first coordinate a picks a column of
// children by the columns' masses (in u) and is rescaled to it; the second
// coordinate b then picks the row inside that column by the masses of its
// children (in v) and is rescaled; the point descends into that child. A
// child's mass is a difference of the tree's running sums (its leaves are
// contiguous along the curve); children are matched to their (column, row)
// through the curve's orientation tables (core/curve.h). Inside the leaf the
// point is placed by the leaf model's marginal and conditional inverse CDFs
// (core/leaf_model.h): exactly, for a quadratic that is not negative on the
// cell (in the coordinates its power laws warp); else, and for the piecewise
// model, by the same column/row split over the model's clamped sub-square
// integrals (the piecewise model's own pieces, or 32 x 32 / 27 x 27 cells)
// and uniformly inside the sub-square. Every step maps a uniform point of
// its square to a point distributed as the mass there, so the composite map
// sends the uniform measure to the tree's mass exactly.
//
// The point is then recorded by its address: its leaf and the digits of the
// leaf's own curve, continuation_levels() below the leaf (2^-26 of the leaf
// for Hilbert, 3^-16 for the 3x3 curves), which sort a set into curve order;
// the sample sits at the centre of that sub-cell, as core/leaf_walk.h places
// the samples of the 1D sequences.
//
// Thread-safety: immutable after construction; Map is thread-safe. The result
// is a pure function of (tree, a, b): plain IEEE arithmetic in a fixed order.
#ifndef SFCSAMPLER_CORE_TREE_WARP_H_
#define SFCSAMPLER_CORE_TREE_WARP_H_

#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/curve_samples.h"
#include "core/curve_tree.h"
#include "core/vector_math.h"

namespace sfc {

class TreeWarp {
 public:
  // O(leaves) time and 12 * arity bytes per internal node. REQUIRES: `tree`
  // outlives the warp and has positive total mass.
  explicit TreeWarp(const CurveTree& tree);

  // The address of the image of (a, b) in [0, 1]^2 (values outside are
  // clamped); index is left 0.
  CurveAddress Locate(double a, double b) const {
    CurveAddress at;
    LocateMany(1, &a, &b, &at);
    return at;
  }
  // out[i] = Locate(a[i], b[i]) for i < n, bit for bit: the points descend
  // the tree a level at a time together, so their chains of dependent loads
  // overlap instead of following one another.
  // On the AVX-512F vector path (`path`, for tests) a Hilbert tree's points
  // descend eight lanes to a vector, on the AVX2 path four
  // (the leaves' digits and inverse CDFs likewise), with the same bits.
  void LocateMany(size_t n, const double* a, const double* b, CurveAddress* out,
                  math::VectorPath path = math::BestVectorPath()) const;

  struct Point {
    double u, v;            // unit-square parameters
    double curve_position;  // in [0, 1), as LeafWalk's
  };
  // The sample at `at`. REQUIRES: an address Locate gave.
  Point Place(const CurveAddress& at) const {
    Point p;
    PlaceMany(1, &at, &p.u, &p.v, &p.curve_position);
    return p;
  }
  // Place(at[i]) into u[i], v[i] and curve_position[i] (when not null), i <
  // n, bit for bit: a run of addresses in one leaf (a sorted set's) decodes
  // the leaf's cell once, and the digits are decoded as a batch
  // (Curve::DescendMany).
  void PlaceMany(size_t n, const CurveAddress* at, double* u, double* v,
                 double* curve_position) const;
  // Place(Locate(a, b)).
  Point Map(double a, double b) const { return Place(Locate(a, b)); }

 private:
  // Moves each of m points from node ref[i] (orientation state[i]) down to
  // its leaf, rescaling a[i] and b[i] at each level; ref[i] becomes -leaf -
  // 1. G is the curve's grid.
  template <int G>
  void Descend(size_t m, double* a, double* b, int32_t* ref, uint8_t* state) const;
  // Places (a, b) inside leaf l, in the leaf's unit coordinates.
  void PlaceInLeaf(size_t l, double a, double b, double* x, double* y) const;
  // digits[i]: the digits of the leaf's curve, continuation_levels() deep,
  // of the sub-cell holding (x[i], y[i]) of a leaf with orientation
  // state[i], i < m <= 64.
  void DigitsInLeaf(size_t m, const double* x, const double* y, const uint8_t* state,
                    uint64_t* digits, math::VectorPath path) const;

  const CurveTree& tree_;
  const Curve& curve_;
  const int grid_, arity_;
  // Internal nodes in depth-first order, arity_ entries each, by position:
  // the child at column dx, row dy of the node's cell is entry dy * grid + dx,
  // node children_[.] when >= 0, else leaf -children_[.] - 1.
  std::vector<int32_t> children_;
  // Per node, stride 2 (grid + grid^2): the columns' upper bounds as shares
  // of the node's mass (cumulative; 1 from the last column with mass on) and
  // their inverse widths, then the same for the rows of each column (dx * grid
  // + dy). A coordinate a picks the first part with a < bound and becomes
  // (a - lower bound) x inverse width.
  std::vector<double> splits_;
  int stride_ = 0;
  // Encoding the digits of a leaf's curve a chunk of levels at a time:
  // encode_[(state * chunk_cells^2 + Y * chunk_cells + X)] holds the chunk's
  // digits and (in the top byte) the orientation it ends in.
  int chunk_levels_ = 1;
  int chunk_cells_ = 1;  // grid^chunk_levels_
  std::vector<uint64_t> encode_;
  int32_t root_ = 0;
  // child_at_[state * arity + dy * grid + dx]: the child at (dx, dy).
  std::vector<int32_t> child_at_;
  // state_at_[state * arity + dy * grid + dx]: that child's orientation.
  std::vector<int32_t> state_at_;
};

}  // namespace sfc

#endif  // SFCSAMPLER_CORE_TREE_WARP_H_
