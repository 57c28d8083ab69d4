#include "core/leaf_walk.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "core/area_estimator.h"
#include "core/curve_samples.h"
#include "core/slope_batch.h"
#include "core/vector_math.h"

namespace sfc {

namespace {

// Two lanes (the baseline's SSE2 registers).
typedef double Pair __attribute__((vector_size(16)));
typedef int64_t Ints __attribute__((vector_size(16)));

// Below this mass a cell is placed uniformly: FollowSlope squares p.
constexpr double kLeastSlopedMass = 1e-150;

// The q of FollowSlope, with p = mass, for a cell with `mass` and `lower` on
// its lower half: the linear density with the same halves, clamped to stay
// >= 0.
double SlopeOf(double mass, double lower) {
  return std::clamp(2 * (mass - 2 * lower), -mass, mass);
}

// Sizes `bounds` for `cells` cells and the scan_width entries of +inf past
// them that LeafWalk::CellsAtOrBelow reads in whole windows; the cells'
// entries are left for the caller to write, so its memory is reused as is.
void SizeBounds(std::vector<double>& bounds, int cells, int scan_width) {
  bounds.resize(cells + scan_width);
  std::fill(bounds.begin() + cells, bounds.end(), std::numeric_limits<double>::infinity());
}

// The fewest curve levels whose cells number at least `cells` a side.
int LevelsForCells(const Curve& curve, int cells) {
  int levels = 1;
  while (curve.PowG(levels) < static_cast<uint64_t>(cells)) ++levels;
  return levels;
}

}  // namespace

LeafWalk::LeafWalk(const CurveTree& tree, const Surface& surface, const Density& density)
    : tree_(tree),
      surface_(surface),
      density_(density),
      curve_(tree.curve()),
      grid_(curve_.grid()),
      exact_levels_(LevelsForCells(curve_, kExactCells)),
      continuation_levels_(curve_.continuation_levels()),
      continuation_scale_(curve_.PowW(continuation_levels_)),
      continuation_cells_(curve_.PowG(continuation_levels_)),
      inverse_cells_(1 / continuation_cells_),
      total_mass_(tree.total_mass()),
      grade_samples_(std::ldexp(1.0, tree.grade())) {
  int exponent;
  cells_power_of_two_ = std::frexp(continuation_cells_, &exponent) == 0.5;
  tables_.resize(kMaxModelLevels + 1);
  unit_axes_.resize(curve_.table_levels() + 1);
  for (int levels = 1; levels <= curve_.table_levels(); ++levels) {
    ComputeAxisFactors(0, 1, static_cast<int>(curve_.PowG(levels)), &unit_axes_[levels]);
  }
  factors_.resize(kMaxModelLevels + 1);
  last_positive_leaf_ = tree.leaf_count() - 1;
  while (last_positive_leaf_ > 0 &&
         !(tree.mass_end(last_positive_leaf_) > tree.mass_begin(last_positive_leaf_))) {
    --last_positive_leaf_;
  }
}

size_t LeafWalk::LeafFor(double m) const {
  // The first leaf with S_l > m. Leaves before the current one end at or
  // below its S_{l-1}, so from there it is the first such leaf overall.
  const size_t leaves = tree_.leaf_count();
  size_t l = 0;
  if (leaf_ != SIZE_MAX && m >= begin_mass_) {
    l = leaf_;
    // Most samples stay in their leaf or move to the next few.
    for (int step = 0; step < 4 && l < leaves; ++step, ++l) {
      if (tree_.mass_end(l) > m) return l;
    }
  }
  l = tree_.FirstLeafEndingAbove(m, l);
  // q_k S_M can round up to S_M itself: it then belongs to the last leaf with mass.
  return l >= leaves ? last_positive_leaf_ : l;
}

void LeafWalk::Enter(size_t l) {
  leaf_ = l;
  begin_mass_ = tree_.mass_begin(l);
  end_mass_ = tree_.mass_end(l);
  leaf_mass_ = end_mass_ - begin_mass_;
  cell_ = tree_.LeafCell(l);
  leaf_start_ = static_cast<double>(tree_.leaf_start(l));
  leaf_span_ = static_cast<double>(tree_.leaf_end(l) - tree_.leaf_start(l));
  model_ = &tree_.leaf_model(l);
  kind_ = tree_.leaf_model_kind(l);
  warped_ = kind_ == LeafModel::Kind::kQuadratic &&
            (model_->warp[0].power != 1 || model_->warp[1].power != 1);
  // Samples' worth at the tree's grade, not the sequence's count: a
  // progressive set extended on the same tree keeps its prefix.
  samples_ = leaf_mass_ / total_mass_ * grade_samples_;
  // Below the rough floor a leaf under a rough parent was never examined:
  // a step may cut it. Above it, it passed the rough test and its model holds.
  if (warped_) split_[0] = WarpSplit(model_->warp[0]), split_[1] = WarpSplit(model_->warp[1]);
  exact_ = tree_.leaf_rough_parent(l) && samples_ < CurveTree::kRoughFloor &&
           kind_ == LeafModel::Kind::kQuadratic && !warped_;
}

int LeafWalk::TableLevels(double carried, int depth) const {
  if (!(carried >= (depth == 0 ? kNegligibleSamples : kTableSamples))) return 0;
  const int most = std::min(curve_.table_levels(), kMaxModelLevels - depth);
  int levels = 1;
  while (levels < most && carried > kCellSamples * static_cast<double>(curve_.PowW(levels)))
    ++levels;
  return std::max(0, std::min(levels, most));
}

int LeafWalk::Tabulate(const Square& square, int levels, std::vector<double>& bounds,
                       GridFactors& factors) {
  const int n = static_cast<int>(curve_.PowG(levels));
  const int cells = n * n;
  if (square.x0 == 0 && square.y0 == 0 && square.side == 1 &&
      HasQuadraticGridFactors(*model_, kind_)) {
    // A leaf's own table: its axes' integrals are every leaf's.
    const AxisFactors& axis = unit_axes_[levels];
    QuadraticGridFactors(*model_, axis, axis, &factors);
  } else {
    ComputeGridFactors(*model_, kind_, grid_, square.x0, square.y0, square.side, n, &factors);
  }
  const Curve::Child* order = curve_.CellsInOrder(square.state, levels);
  SizeBounds(bounds, cells, kScanWidth);
  // Running sums in curve order of the cells' integrals (GridFactors;
  // a quadratic's dips below zero count as no mass).
  double sum = 0;
  for (int k = 0; k < cells; ++k) {
    sum += std::max(0.0, factors.Integral(order[k].dx, order[k].dy));
    bounds[k] = sum;
  }
  if (!(sum > 0)) return -1;  // the model vanishes here: pure curve bits
  int last = cells - 1;
  while (last > 0 && bounds[last - 1] == sum) --last;
  // Running sums to t: monotone, so the bounds do not decrease.
  const double scale = (square.t1 - square.t0) / sum;
  for (int k = 0; k < last; ++k) bounds[k] = std::min(square.t0 + bounds[k] * scale, square.t1);
  for (int k = last; k < cells; ++k) bounds[k] = square.t1;
  return last;
}

int LeafWalk::TabulateExact(const Square& leaf, int levels, std::vector<double>& bounds) {
  const int n = static_cast<int>(curve_.PowG(levels));
  cell_us_.resize(n), cell_vs_.resize(n), cell_m_.resize(static_cast<size_t>(n) * n);
  for (int i = 0; i < n; ++i) {
    const double centre = (i + 0.5) / n;
    cell_us_[i] = cell_.u0 + centre * cell_.size;
    cell_vs_[i] = cell_.v0 + centre * cell_.size;
  }
  MassDensityGrid(surface_, density_, cell_us_.data(), n, cell_vs_.data(), n, cell_m_.data());
  const Curve::Child* order = curve_.CellsInOrder(leaf.state, levels);
  const int cells = n * n;
  SizeBounds(bounds, cells, kScanWidth);
  // Running sums in curve order (the cells are equal, so densities will do).
  double sum = 0;
  for (int k = 0; k < cells; ++k) {
    const double m = cell_m_[static_cast<size_t>(order[k].dx) * n + order[k].dy];
    if (!(m >= 0 && m < INFINITY)) return -1;
    sum += m;
    bounds[k] = sum;
  }
  if (!(sum > 0)) return -1;
  int last = cells - 1;
  while (last > 0 && bounds[last - 1] == sum) --last;
  for (int k = 0; k < last; ++k) bounds[k] = std::min(bounds[k] / sum, 1.0);
  for (int k = last; k < cells; ++k) bounds[k] = 1;
  return last;
}

void LeafWalk::Place(const double* m, size_t n, double* u, double* v, double* curve_position) {
  u_ = u, v_ = v, curve_position_ = curve_position;
  // kScanWidth entries past the run: PrefixBelow and Reached read and write
  // whole windows.
  t_.resize(n + kScanWidth), reached_of_.resize(n + kScanWidth);
  reached_.clear(), frames_.clear(), warped_runs_.clear();
  // Samples [waiting, i) have their squares and wait for Continue, up to
  // kContinueBatch of them, warped leaves' among them (each leaf's warp is
  // in its frame).
  size_t waiting = 0;
  const auto flush = [&](size_t end) {
    Continue(waiting, end);
    reached_.clear(), frames_.clear(), warped_runs_.clear();
    waiting = end;
  };
  size_t i = 0;
  while (i < n) {
    const size_t l = LeafFor(m[i]);
    if (l != leaf_) Enter(l);
    // The run of samples in this leaf with non-decreasing m. From m[i] on,
    // m < S_l alone puts a sample here.
    size_t j = i + 1;
    while (j < n && m[j] >= m[j - 1] && (m[j] < end_mass_ || LeafFor(m[j]) == l)) ++j;
    PlaceInLeaf(m + i, i, j - i);
    if (warped_) warped_runs_.push_back({i, j, static_cast<uint32_t>(frames_.size() - 1)});
    if (j - waiting >= kContinueBatch) flush(j);
    i = j;
  }
  flush(n);
}

void LeafWalk::PlaceInLeaf(const double* m, size_t begin, size_t n) {
  for (size_t i = 0; i < n; ++i) {
    t_[begin + i] = std::clamp((m[i] - begin_mass_) / leaf_mass_, 0.0, 1.0);
  }
  const uint32_t frame = static_cast<uint32_t>(frames_.size());
  Frame leaf_frame{cell_.u0, cell_.v0, cell_.size, leaf_start_, leaf_span_, warped_, {}, {}};
  leaf_frame.warp[0] = model_->warp[0], leaf_frame.warp[1] = model_->warp[1];
  leaf_frame.split[0] = split_[0], leaf_frame.split[1] = split_[1];
  frames_.push_back(leaf_frame);
  const Square leaf{0, 1, 0, 0, 1, 0, 1, 1, 0, 0, cell_.state, 0, frame};
  PlaceInSquare(leaf, static_cast<uint32_t>(begin), static_cast<uint32_t>(begin + n), 0);
}

__attribute__((always_inline)) inline int LeafWalk::CellsAtOrBelow(const double* bounds, int from,
                                                                   double t) {
  // A window of kScanWidth comparisons at a time, without branches inside:
  // the count of bounds <= t there is how far to move (they do not decrease).
  while (true) {
    int count = 0;
    for (int d = 0; d < kScanWidth; ++d) count += bounds[from + d] <= t;
    from += count;
    if (count < kScanWidth) return from;
  }
}

__attribute__((always_inline)) inline uint32_t LeafWalk::PrefixBelow(const double* t,
                                                                     uint32_t begin, uint32_t end,
                                                                     double bound) {
  // As CellsAtOrBelow: a window at a time, without branches inside.
  while (true) {
    int count = 0;
    for (int d = 0; d < kScanWidth; ++d) count += (begin + d < end) & (t[begin + d] < bound);
    begin += count;
    if (count < kScanWidth) return begin;
  }
}

void LeafWalk::Reached(const Square& square, uint32_t begin, uint32_t end) {
  const uint32_t index = static_cast<uint32_t>(reached_.size());
  reached_.push_back(square);
  // Whole windows: the entries written past `end` are later samples', which
  // get theirs later in the walk (samples reach their squares in order).
  for (uint32_t i = begin; i < end; i += kScanWidth) {
    for (int d = 0; d < kScanWidth; ++d) reached_of_[i + d] = index;
  }
}

void LeafWalk::PlaceInSquare(const Square& square, uint32_t begin, uint32_t end, int level) {
  int levels = TableLevels((square.t1 - square.t0) * samples_, square.depth);
  std::vector<double>& bounds = tables_[level];
  int last = -1;
  if (exact_ && level == 0) {
    last = TabulateExact(square, exact_levels_, bounds);
    if (last >= 0) levels = exact_levels_;
  }
  // Cells of a model table follow the model's slope inside; an exact
  // table's cells are uniform (its leaf carries under kRoughFloor samples).
  const bool sloped = last < 0;
  const GridFactors& factors = factors_[level];
  if (last < 0 && levels > 0) last = Tabulate(square, levels, bounds, factors_[level]);
  if (last < 0) {
    Reached(square, begin, end);
    return;
  }
  const Curve::Child* order = curve_.CellsInOrder(square.state, levels);
  const double side = square.side / curve_.PowG(levels);
  const double span = square.span / static_cast<double>(curve_.PowW(levels));
  // Cell k takes samples [i, j) of the square (k's bound is above their t,
  // and the earlier cells' bounds are not).
  const auto place = [&](int k, uint32_t i, uint32_t j) {
    Square cell;
    cell.t0 = k == 0 ? square.t0 : bounds[k - 1], cell.t1 = bounds[k];
    cell.x0 = square.x0 + order[k].dx * side, cell.y0 = square.y0 + order[k].dy * side;
    cell.side = side;
    cell.pos = square.pos + k * span, cell.span = span;
    cell.state = order[k].state;
    cell.depth = square.depth + levels;
    cell.frame = square.frame;
    cell.mass = 1, cell.gx = cell.gy = 0;
    if (level < kMaxModelLevels && (cell.t1 - cell.t0) * samples_ >= kTableSamples) {
      PlaceInSquare(cell, i, j, level + 1);
    } else {
      const int x = order[k].dx, y = order[k].dy;
      const double mass = sloped ? factors.Integral(x, y) : 0;
      if (mass > kLeastSlopedMass) {
        cell.mass = mass;
        if (factors.halves[0]) cell.gx = SlopeOf(mass, factors.LowerX(x, y));
        if (factors.halves[1]) cell.gy = SlopeOf(mass, factors.LowerY(x, y));
      }
      Reached(cell, i, j);
    }
  };
  // Samples in t order meet the cells in curve order: t goes to the first
  // cell whose bound is above it (that cell has mass), and t >= t1 to the
  // last. So the cells before the last hold the samples whose t is below
  // their bound, the last one the rest.
  if (end - begin <= static_cast<uint32_t>(kScanWidth) && last < kSmallTableCells) {
    // A few samples in a small table: each cell's end counted on its own,
    // with no chain from one cell's samples to the next cell's.
    // The samples' t in pairs (SSE2 registers), +inf past the square's end.
    constexpr int kPairs = kScanWidth / 2;
    Pair t[kPairs];
    const int64_t count = end - begin;
    for (int d = 0; d < kPairs; ++d) {
      Pair pair;
      std::memcpy(&pair, &t_[begin + 2 * d], sizeof pair);
      const Ints inside = Ints{2 * d, 2 * d + 1} < count;
      t[d] = inside ? pair : Pair{} + std::numeric_limits<double>::infinity();
    }
    uint32_t ends[kSmallTableCells];
    for (int k = 0; k < last; ++k) {
      Ints below{};  // -1 for each t below the bound
      for (int d = 0; d < kPairs; ++d) below += t[d] < bounds[k];
      ends[k] = begin + static_cast<uint32_t>(-(below[0] + below[1]));
    }
    uint32_t i = begin;
    for (int k = 0; k <= last && i < end; ++k) {
      const uint32_t j = k == last ? end : ends[k];
      if (j > i) place(k, i, j);
      i = std::max(i, j);
    }
    return;
  }
  int first = 0;  // bounds below first are <= every t from here on
  uint32_t i = begin;
  while (i < end) {
    first = CellsAtOrBelow(bounds.data(), first, t_[i]);
    const int k = std::min(first, last);
    // Sample i is below bounds[k] unless k is the last cell, which takes the rest.
    const uint32_t j = k == last ? end : PrefixBelow(t_.data(), i + 1, end, bounds[k]);
    place(k, i, j);
    i = j;
  }
}

void LeafWalk::Continue(size_t begin, size_t end) {
  // The rest of t down its square's own curve, to the centre of the cell
  // reached: the curve digits of all n samples first, then one batch of
  // curve decoding, then the coordinates. Arrays of the batch are indexed
  // from `begin`.
  if (end <= begin) return;
  const size_t n = end - begin;
  const uint32_t* square_of = reached_of_.data() + begin;
  const uint64_t scale = continuation_scale_;
  fraction_.resize(n), digits_.resize(n), states_.resize(n), cx_.resize(n), cy_.resize(n);
  for (size_t i = 0; i < n; ++i) {
    const Square& at = reached_[square_of[i]];
    const double t = t_[begin + i];
    const double tr = at.t1 > at.t0 ? std::clamp((t - at.t0) / (at.t1 - at.t0), 0.0, 1.0) : 0.0;
    fraction_[i] = tr;
    // Conversions through int64_t: every value here is below 2^63, so they
    // are exact either way, and the signed ones are single instructions.
    digits_[i] = std::min(
        static_cast<uint64_t>(static_cast<int64_t>(tr * static_cast<double>(scale))), scale - 1);
    states_[i] = static_cast<uint64_t>(at.state);
  }
  curve_.DescendMany(digits_.data(), continuation_levels_, n, states_.data(), cx_.data(),
                     cy_.data());
  // The centre of the continuation's cell in cells, and its square's slope
  // (FollowSlope's p and q), then the fractions of the square for all n in
  // one vectorised pass (slope_batch.h).
  fx_.resize(n), fy_.resize(n), mass_.resize(n), gx_.resize(n), gy_.resize(n);
  for (size_t i = 0; i < n; ++i) {
    const Square& at = reached_[square_of[i]];
    fx_[i] = static_cast<double>(static_cast<int64_t>(cx_[i])) + 0.5;
    fy_[i] = static_cast<double>(static_cast<int64_t>(cy_[i])) + 0.5;
    mass_[i] = at.mass, gx_[i] = at.gx, gy_[i] = at.gy;
  }
  // For Hilbert the division is by 2^26: a multiplication, with the same bits.
  slope_batch::FollowSlopes(fx_.data(), mass_.data(), gx_.data(), n, cells_power_of_two_,
                            continuation_cells_, inverse_cells_);
  slope_batch::FollowSlopes(fy_.data(), mass_.data(), gy_.data(), n, cells_power_of_two_,
                            continuation_cells_, inverse_cells_);
  for (size_t i = 0; i < n; ++i) {
    const Square& at = reached_[square_of[i]];
    const Frame& leaf = frames_[at.frame];
    if (!leaf.warped) {
      const double px = at.x0 + fx_[i] * at.side, py = at.y0 + fy_[i] * at.side;
      u_[begin + i] = leaf.u0 + px * leaf.size;
      v_[begin + i] = leaf.v0 + py * leaf.size;
    }
    if (curve_position_ != nullptr) {
      const double pos = at.pos + fraction_[i] * at.span;
      curve_position_[begin + i] =
          CurvePosition(leaf.start + pos * leaf.span, static_cast<double>(curve_.Span(0)));
    }
  }
  for (const WarpedRun& run : warped_runs_) {
    const Frame& leaf = frames_[run.frame];
    const size_t at = run.begin - begin, count = run.end - run.begin;
    PlaceWarped(leaf, 0, run.begin, count, fx_.data() + at, u_ + run.begin);
    PlaceWarped(leaf, 1, run.begin, count, fy_.data() + at, v_ + run.begin);
  }
}

void LeafWalk::PlaceWarped(const Frame& leaf, int axis, size_t begin, size_t n, const double* f,
                           double* out) {
  // Warp's and Unwarp's operations in order, their powers taken in batch
  // calls (the same bits as the one-value functions).
  const AxisWarp& w = leaf.warp[axis];
  const double sc = leaf.split[axis], k = w.power;
  const double origin = axis == 0 ? leaf.u0 : leaf.v0;
  auto square = [&](size_t i) -> const Square& { return reached_[reached_of_[begin + i]]; };
  auto lower = [&](size_t i) { return axis == 0 ? square(i).x0 : square(i).y0; };
  base_.resize(2 * n), power_.resize(2 * n), place_.resize(n);
  double* base = base_.data();
  double* power = power_.data();
  double* s = place_.data();
  if (w.power == 1) {
    for (size_t i = 0; i < n; ++i) s[i] = lower(i) + f[i] * square(i).side;
  } else if (DescendsWarped(w)) {
    // The curve ran in warped coordinates: W of the point reached.
    for (size_t i = 0; i < n; ++i) {
      s[i] = lower(i) + f[i] * square(i).side;
      base[i] = WarpBase(w, sc, s[i]);
    }
    math::Pow(base, k, n, power);
    for (size_t i = 0; i < n; ++i) s[i] = WarpFrom(w, sc, s[i], power[i]);
  } else {
    // Uniform in warped coordinates inside the cell [x0, x0 + side]: its
    // ends through W^-1, the point between them through W.
    for (size_t i = 0; i < n; ++i) {
      const double x0 = lower(i);
      base[2 * i] = UnwarpBase(w, x0), base[2 * i + 1] = UnwarpBase(w, x0 + square(i).side);
    }
    math::Pow(base, 1 / k, 2 * n, power);
    for (size_t i = 0; i < n; ++i) {
      const double x0 = lower(i), x1 = x0 + square(i).side;
      const double s0 = UnwarpFrom(w, sc, x0, power[2 * i]);
      const double s1 = UnwarpFrom(w, sc, x1, power[2 * i + 1]);
      s[i] = s0 + f[i] * (s1 - s0);
      base[i] = WarpBase(w, sc, s[i]);
    }
    math::Pow(base, k, n, power);
    for (size_t i = 0; i < n; ++i) {
      const double x0 = lower(i);
      s[i] = std::clamp(WarpFrom(w, sc, s[i], power[i]), x0, x0 + square(i).side);
    }
  }
  for (size_t i = 0; i < n; ++i) out[i] = origin + s[i] * leaf.size;
}

}  // namespace sfc
