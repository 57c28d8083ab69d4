// Placement of samples by their mass coordinates (paper Fig. 1 line 8;
// docs/ALGORITHM.md step 4 and "Inside a leaf, follow the model"), as a walk.
//
// Mass coordinate m = q_k S_M lands in the leaf l with S_{l-1} <= m < S_l.
// Inside it, t = (m - S_{l-1}) / s_l descends the leaf's own curve, at each
// level entering the child whose share of the model's exact integral holds t,
// until the sub-cell reached carries less than kNegligibleSamples of one
// sample (counted at the tree's grade, so every sequence on one tree places a
// given t alike). The rest of t is followed as pure curve bits for
// continuation_levels() more levels, and the sample sits at the centre of the
// cell reached. In a leaf whose model is warped toward a singular line
// (LeafModel::warp) where the area element blows up, the leaf's curve runs in
// the warped coordinates, where the model is smooth, and the point reached is
// mapped back through the warp: the paper's reparameterisation (Sect. 5.3)
// inside one leaf, whose cells are then thin strips along the line. Where it
// vanishes, the curve stays in leaf coordinates and the continuation inside
// the last sub-cell is uniform in warped ones (DescendsWarped).
//
// Coordinates handed over in non-decreasing order make this a merge: the
// leaf advances by a forward step, and the samples of one leaf descend
// together, level by level: each model sub-cell that holds samples is
// integrated once for all of them, the sub-cells of one level one after
// another with no sample's branches in between, and the samples are then
// split among the children in order. The result is a pure function of
// (tree, m): a sub-cell's values are computed the same way whichever samples
// it holds, so any split of a run of samples between calls or walks gives
// the same bits.
//
// Thread-safety: a LeafWalk is used by one thread at a time; many walks may
// share one tree.
#ifndef SFCSAMPLER_CORE_LEAF_WALK_H_
#define SFCSAMPLER_CORE_LEAF_WALK_H_

#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/curve_tree.h"

namespace sfc {

class LeafWalk {
 public:
  // Below this many samples' worth a sub-cell's placement is pure curve bits.
  static constexpr double kNegligibleSamples = 1.0 / 8;
  // The model descent stops after this many levels in any case.
  static constexpr int kMaxModelLevels = 40;

  // REQUIRES: `tree` outlives the walk and has positive total mass.
  explicit LeafWalk(const CurveTree& tree);

  // Places the n mass coordinates m[0..n) (each in [0, S_M]): u[i], v[i] get
  // sample i's unit-square parameters and, when `curve_position` is not
  // null, curve_position[i] its position along the curve in [0, 1). Any
  // order is accepted; a non-decreasing one is a walk (a step back starts a
  // search).
  void Place(const double* m, size_t n, double* u, double* v, double* curve_position);

 private:
  // A sub-cell of the model descent: leaf-fraction interval [t0, t1), its
  // square [x0, x0 + side) x [y0, y0 + side) in leaf units, its orientation,
  // its start along the leaf's curve (a fraction of the leaf's span), and the
  // run's samples it holds.
  struct Node {
    double t0, t1, x0, y0, side, pos, span;  // span: the node's share of the leaf's curve
    int state;
    int depth;               // 0 for the leaf itself
    uint32_t begin, end;     // its samples: [begin, end) of the run
    bool split;              // children's bounds[] filled
    bool ordered;            // bounds[] is non-decreasing (all but rounding corners)
    double bounds[9];        // upper t of each child, in curve order
  };

  // Leaf coordinate along one axis of the point at x in the sub-cell
  // [x0, x0 + side] the descent reached (DescendsWarped: x is warped).
  static double PlaceOnAxis(const AxisWarp& w, double x0, double side, double x);
  // The leaf holding m: a forward step from the current one, else a search.
  size_t LeafFor(double m) const;
  // Makes l the current leaf.
  void Enter(size_t l);
  // Fills the node's child bounds from the model; false where the model
  // vanishes (its samples then follow pure curve bits from there).
  template <int kGrid>
  bool Split(Node& node) const;
  // The child of `node` holding t: the first whose interval [t0, bounds[c])
  // is not empty and holds t; w when rounding left t past the last one.
  template <int kArity>
  static int ChildHolding(const Node& node, double t);
  // Places n samples of the current leaf with non-decreasing m.
  template <int kGrid>
  void PlaceInLeaf(const double* m, size_t n, double* u, double* v, double* curve_position);

  const CurveTree& tree_;
  const Curve& curve_;
  const int grid_;
  const int continuation_levels_;
  const uint64_t continuation_scale_;  // w^continuation_levels
  const double continuation_cells_;    // g^continuation_levels
  const double inverse_cells_;         // its inverse, exact when it is a power of two
  bool cells_power_of_two_ = false;
  const double total_mass_;            // S_M
  const double grade_samples_;         // 2^grade: samples in S_M at the tree's grade
  size_t last_positive_leaf_ = 0;      // where m = S_M belongs

  size_t leaf_ = SIZE_MAX;  // the current leaf, SIZE_MAX before the first
  double begin_mass_ = 0, end_mass_ = 0, leaf_mass_ = 0, samples_ = 0;
  CurveTree::Cell cell_{};
  double leaf_start_ = 0, leaf_span_ = 0;  // curve indices, for curve_position
  const LeafModel* model_ = nullptr;
  LeafModel::Kind kind_ = LeafModel::Kind::kQuadratic;
  bool warped_ = false;  // the model has a power law (LeafModel::warp)
  // Scratch of PlaceInLeaf, kept to reuse its memory.
  std::vector<double> t_;           // each sample's fraction of the leaf's mass
  std::vector<Node> nodes_;         // the descent's sub-cells, level by level
  std::vector<uint32_t> final_;     // each sample's deepest node
};

}  // namespace sfc

#endif  // SFCSAMPLER_CORE_LEAF_WALK_H_
