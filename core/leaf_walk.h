// Placement of samples by their mass coordinates (paper Fig. 1 line 8;
// docs/ALGORITHM.md step 4 and "Inside a leaf, follow the model"), as a walk.
//
// Mass coordinate m = q_k S_M lands in the leaf l with S_{l-1} <= m < S_l.
// Inside it, t = (m - S_{l-1}) / s_l is placed by an inverse CDF at fixed
// resolution: the leaf's square is cut into the n x n cells some levels of
// its own curve reach (a table), the model's exact integral over each cell is
// summed in curve order, and t falls into the cell whose share of the sum
// holds it. The table is as fine as the leaf's samples need, kCellSamples
// a cell or less (counted at the tree's grade, so every sequence on one tree
// places a given t alike, and limited to 32 x 32 cells); a cell that still
// carries many samples, where the mass is uneven or the leaf is large, gets
// a table of its own. The rest of t is followed as pure curve bits for
// continuation_levels() more levels, to the centre of the cell reached, and
// that point is moved inside its table cell to follow the mass's slope
// there: along each axis, the inverse CDF of the linear density with the
// model's masses over the cell's two halves (FollowSlope), a monotone
// bijection of the cell onto itself, so the curve's stratification is kept
// and the gradient's bias of order the cell's area is gone (docs/QUALITY.md,
// "Placement that follows the slope"). In a leaf whose model is warped
// toward a singular line (LeafModel::warp) where the area element blows up,
// the tables run in the warped coordinates, where the model is smooth, and
// the point reached is mapped back through the warp: the paper's
// reparameterisation (Sect. 5.3) inside one leaf, whose cells are then thin
// strips along the line; the slope is followed there in warped coordinates.
// Where it vanishes, the tables stay in leaf coordinates and the continuation
// inside the last cell is uniform in warped ones (DescendsWarped), with no
// slope along that axis.
//
// A leaf whose parent was rough (CurveTree::leaf_rough_parent) and whose
// quadratic is not warped may be cut by a step or crease that its quadratic
// cannot see when it carries less than CurveTree::kRoughFloor samples: the
// tree does not examine it, and its model would spread a step's mass across
// the whole leaf. The first table of such a leaf is made of the true mass
// density at the centres of its cells (kExactCells a side), so samples land
// on the right side of a step to an eighth of the leaf (docs/ALGORITHM.md,
// "Features inside a leaf").
//
// Coordinates handed over in non-decreasing order make this a merge: the
// leaf advances by a forward step, a table is made once for the samples of
// its square, and they are matched to its cells by a forward step too. The
// result is a pure function of (tree, m): a table's values depend only on
// its square, so any split of a run of samples between calls or walks gives
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
#include "core/density.h"
#include "core/surface.h"

namespace sfc {

class LeafWalk {
 public:
  // Below this many samples' worth a leaf's placement is pure curve bits.
  static constexpr double kNegligibleSamples = 1.0 / 8;
  // A table's cells carry at most this many samples on average. Inside a
  // cell the sample follows the curve and the mass's slope (FollowSlope);
  // what it misses is of second order in the cell's side: the Monte Carlo
  // check beside singular lines gives the same figures from 1/4 to 32
  // samples a cell (docs/QUALITY.md, "Placement that follows the slope",
  // "32 samples a cell"). Fewer, larger cells are what the sphere's kernel
  // costs least with: 32 took 1.7x less time a sample than 4, 64 no less.
  static constexpr double kCellSamples = 32;
  // A table cell carrying at least this many samples gets a table of its own.
  static constexpr double kTableSamples = 4 * kCellSamples;
  // Tables stop this many curve levels below the leaf in any case.
  static constexpr int kMaxModelLevels = 40;

  // Cells a side of the first table of a leaf under a rough parent: the
  // curve levels that reach at least this many (8 for Hilbert, 9 for the
  // 3x3 curves).
  static constexpr int kExactCells = 8;

  // REQUIRES: `tree` was built from `surface` and `density`, has positive
  // total mass, and all three outlive the walk.
  LeafWalk(const CurveTree& tree, const Surface& surface, const Density& density);

  // Places the n mass coordinates m[0..n) (each in [0, S_M]): u[i], v[i] get
  // sample i's unit-square parameters and, when `curve_position` is not
  // null, curve_position[i] its position along the curve in [0, 1). Any
  // order is accepted; a non-decreasing one is a walk (a step back starts a
  // search). REQUIRES: n < 2^32 (samples are indexed by uint32_t).
  void Place(const double* m, size_t n, double* u, double* v, double* curve_position);

 private:
  // A square reached inside a leaf (frames_[frame]; samples wait for
  // Continue after the walk has left their leaf): leaf-fraction interval
  // [t0, t1), its square [x0, x0 + side) x [y0, y0 + side) in leaf units (in
  // the coordinates the walk descends in), its orientation, its start and
  // share along the leaf's curve (fractions of the leaf's span), and how many
  // curve levels below the leaf it is.
  // mass, gx, gy: FollowSlope's p and q along x and y, the density across
  // the square along x being 1 + (gx / mass)(2s - 1) at fraction s (gx = gy
  // = 0: uniform, where no model table reached the square).
  // frame: its leaf's entry in frames_.
  struct Square {
    double t0, t1, x0, y0, side, pos, span, mass, gx, gy;
    int state;
    int depth;
    uint32_t frame;
  };
  // Where a leaf's unit square lies in the surface's parameters, its span
  // along the curve, and its model's warp (with WarpSplit of each axis's,
  // when warped): what Continue reads of a leaf whose samples it places
  // after the walk has left it.
  struct Frame {
    double u0, v0, size, start, span;
    bool warped;
    AxisWarp warp[2];
    double split[2];
  };
  // Samples [begin, end) of the run, all of the warped leaf frames_[frame].
  struct WarpedRun {
    size_t begin, end;
    uint32_t frame;
  };
  // Leaves with fewer samples than this wait for the next leaves' and have
  // their curve bits followed in one batch (Continue): the batch calls are
  // vectorised, and a leaf of a dozen samples filled few lanes.
  static constexpr size_t kContinueBatch = 1024;

  // The run's samples [begin, begin + n), in the leaf `leaf`, whose model is
  // warped along `axis` (0: u, 1: v): out[i] gets the parameter of the point
  // at fraction f[i] of the cell [x0, x0 + side] sample begin + i reached
  // along that axis: W of it where the curve descended in warped coordinates
  // (DescendsWarped), else uniform in warped coordinates inside the cell.
  void PlaceWarped(const Frame& leaf, int axis, size_t begin, size_t n, const double* f,
                   double* out);
  // The leaf holding m: a forward step from the current one, else a search.
  size_t LeafFor(double m) const;
  // Makes l the current leaf.
  void Enter(size_t l);
  // Curve levels of the table of a square carrying `carried` samples' worth;
  // 0: none (pure curve bits).
  int TableLevels(double carried, int depth) const;
  // Fills `bounds` with the upper t of each of the square's w^levels table
  // cells in curve order (non-decreasing, the last with mass and all after
  // it ending at t1); returns the index of the last cell with mass, or -1
  // where the model vanishes.
  // `factors` keeps the table's GridFactors, for the cells' slopes.
  int Tabulate(const Square& square, int levels, std::vector<double>& bounds, GridFactors& factors);
  // The same for the whole leaf from the true mass density at the cells'
  // centres; -1 where it is not finite or vanishes (the model's table then).
  int TabulateExact(const Square& leaf, int levels, std::vector<double>& bounds);
  // Finds the squares of the current leaf's samples [begin, end) (indices of
  // the Place call's run), which lie in `square` in t order, using the table
  // of recursion `level`.
  void PlaceInSquare(const Square& square, uint32_t begin, uint32_t end, int level);
  // Bounds compared at once when matching samples to cells.
  static constexpr int kScanWidth = 16;
  // A table of fewer cells than this with at most kScanWidth samples has
  // each cell's samples counted on its own.
  static constexpr int kSmallTableCells = 64;
  // The number of entries of `bounds` that are <= t, counted from `from`,
  // where every entry before `from` is (bounds do not decrease and end in
  // kScanWidth entries of +inf).
  static int CellsAtOrBelow(const double* bounds, int from, double t);
  // The first of samples [begin, end) whose t is at least `bound`, or end:
  // their t do not decrease. Reads t[begin .. end + kScanWidth) in whole
  // windows.
  static uint32_t PrefixBelow(const double* t, uint32_t begin, uint32_t end, double bound);
  // Records that samples [begin, end) end in `square` (pure curve bits from there).
  void Reached(const Square& square, uint32_t begin, uint32_t end);
  // Places samples [begin, end) of the run by pure curve bits inside the
  // squares they reached (those of warped leaves, warped_runs_, through
  // their warps).
  void Continue(size_t begin, size_t end);
  // Finds the squares of the run's samples [begin, begin + n), the current
  // leaf's, with non-decreasing m (Continue places them).
  void PlaceInLeaf(const double* m, size_t begin, size_t n);

  const CurveTree& tree_;
  const Surface& surface_;
  const Density& density_;
  const Curve& curve_;
  const int grid_;
  const int exact_levels_;  // curve levels of an exact table (kExactCells)
  const int continuation_levels_;
  const uint64_t continuation_scale_;  // w^continuation_levels
  const double continuation_cells_;    // g^continuation_levels
  const double inverse_cells_;         // its inverse, exact when it is a power of two
  bool cells_power_of_two_ = false;
  const double total_mass_;        // S_M
  const double grade_samples_;     // 2^grade: samples in S_M at the tree's grade
  size_t last_positive_leaf_ = 0;  // where m = S_M belongs

  size_t leaf_ = SIZE_MAX;  // the current leaf, SIZE_MAX before the first
  double begin_mass_ = 0, end_mass_ = 0, leaf_mass_ = 0, samples_ = 0;
  CurveTree::Cell cell_{};
  double leaf_start_ = 0, leaf_span_ = 0;  // curve indices, for curve_position
  const LeafModel* model_ = nullptr;
  LeafModel::Kind kind_ = LeafModel::Kind::kQuadratic;
  bool warped_ = false;   // the model has a power law (LeafModel::warp)
  double split_[2] = {};  // WarpSplit of each axis's warp, when warped_
  bool exact_ = false;    // the first table follows the true mass density (kExactCells)
  // Scratch of a Place call (indexed by the run's samples), kept to reuse its
  // memory.
  std::vector<double> t_;                           // each sample's fraction of the leaf's mass
  std::vector<std::vector<double>> tables_;         // cell bounds, one table per recursion level
  std::vector<GridFactors> factors_;                // their cell integrals, as factors
  std::vector<AxisFactors> unit_axes_;              // [levels]: a leaf's own table's axes
  std::vector<double> cell_us_, cell_vs_, cell_m_;  // an exact table's centres and densities
  std::vector<Square> reached_;                     // the squares samples end in
  std::vector<Frame> frames_;                       // their leaves
  std::vector<WarpedRun> warped_runs_;              // the samples of warped leaves among them
  std::vector<uint32_t> reached_of_;                // each sample's square in reached_
  std::vector<double> fraction_;                    // each sample's fraction of its square's t
  std::vector<uint64_t> digits_, cx_, cy_;          // its curve digits and the cell they reach
  std::vector<uint64_t> states_;                    // its square's orientation, then the cell's
  std::vector<double> fx_, fy_;                     // its fractions of its square
  std::vector<double> mass_, gx_, gy_;              // its square's FollowSlope p and q
  std::vector<double> base_, power_, place_;        // PlaceWarped's powers and places
  // The Place call's output columns (curve_position_ may be null).
  double *u_ = nullptr, *v_ = nullptr, *curve_position_ = nullptr;
};

}  // namespace sfc

#endif  // SFCSAMPLER_CORE_LEAF_WALK_H_
