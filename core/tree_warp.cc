#include "core/tree_warp.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <functional>

#include "core/leaf_model.h"
#include "core/tree_warp_internal.h"

namespace sfc {
namespace {

// The orientations a curve's cells take: the 8 symmetries of the square.
constexpr int kStates = 8;

using tree_warp_internal::kBelowOne;

// Picks among `n` parts with masses `mass` (not all zero) by the coordinate
// *a in [0, 1): the part holding a x total, with *a rescaled to that part
// (the inverse CDF of the parts, then of the uniform inside one). Zero-mass
// parts are never picked. Used where no bounds are stored (inside leaves).
int Split(const double* mass, int n, double* a) {
  double total = 0;
  for (int i = 0; i < n; ++i) total += mass[i];
  const double t = *a * total;
  double before = 0;
  int last = -1;
  for (int i = 0; i < n; ++i) {
    if (!(mass[i] > 0)) continue;
    last = i;
    if (before + mass[i] > t) break;
    before += mass[i];
  }
  assert(last >= 0);
  *a = std::clamp((t - before) / mass[last], 0.0, kBelowOne);
  return last;
}

// The bounds and inverse widths of parts with masses `mass` (Split's choice
// as stored bounds): bound[i] the cumulative share up to part i, 1 from the
// last part with mass on, so a < 1 always finds a part with mass.
void Bounds(const double* mass, int n, double* bound, double* inverse) {
  double total = 0;
  for (int i = 0; i < n; ++i) total += mass[i];
  int last = 0;
  for (int i = 0; i < n; ++i) {
    if (mass[i] > 0) last = i;
  }
  double before = 0;
  for (int i = 0; i < n; ++i) {
    before += mass[i];
    bound[i] = i >= last || !(total > 0) ? 1.0 : before / total;
    inverse[i] = mass[i] > 0 ? total / mass[i] : 0;
  }
}

// The part of stored bounds that a falls in, and a rescaled to it.
int Pick(const double* bound, const double* inverse, int n, double* a) {
  // The count of bounds at or below a, without branches: bounds do not
  // decrease, and the last is 1 > a.
  int i = 0;
  for (int j = 0; j + 1 < n; ++j) i += *a >= bound[j];
  const double lower = i == 0 ? 0.0 : bound[i - 1];
  *a = std::clamp((*a - lower) * inverse[i], 0.0, kBelowOne);
  return i;
}

// p(s) = p0 + p1 s + p2 s^2 >= 0 on [0, 1].
bool NotNegative(double p0, double p1, double p2) {
  if (p0 < 0 || p0 + p1 + p2 < 0) return false;
  if (p2 > 0) {
    const double s = -p1 / (2 * p2);
    if (s > 0 && s < 1 && p0 + s * (p1 + s * p2) < 0) return false;
  }
  return true;
}

// The s in [0, 1] where the CDF F(s) = p0 s + p1 s^2 / 2 + p2 s^3 / 3 of a
// density p not negative on [0, 1] reaches `share` of F(1): Newton's method
// kept inside a shrinking bracket (bisection where a step leaves it). One
// problem's state, so that a batch can take its steps side by side.
class CdfInversion {
 public:
  CdfInversion() = default;
  CdfInversion(const double p[3], double share)
      : p0_(p[0]), p1_(p[1]), p2_(p[2]), target_(share * Cdf(1)), s_(share) {}
  // One step; true when done, with the answer in s().
  bool Step() {
    const double f = Cdf(s_) - target_;
    if (f == 0) return true;
    if (f > 0) {
      hi_ = s_;
    } else {
      lo_ = s_;
    }
    const double d = p0_ + s_ * (p1_ + s_ * p2_);
    double next = d > 0 ? s_ - f / d : (lo_ + hi_) / 2;
    if (!(next > lo_ && next < hi_)) next = (lo_ + hi_) / 2;
    // A step below 2^-44 of the leaf is far below the address's 2^-26
    // (Hilbert; 3^-16 for the 3x3 curves) resolution.
    const bool done = std::fabs(next - s_) <= 0x1.0p-44 || hi_ - lo_ <= 0x1.0p-52;
    s_ = next;
    return done;
  }
  double s() const { return s_; }
  static constexpr int kMaxSteps = tree_warp_internal::kCdfMaxSteps;

 private:
  double Cdf(double s) const { return s * (p0_ + s * (p1_ / 2 + s * (p2_ / 3))); }
  double p0_ = 0, p1_ = 0, p2_ = 0, target_ = 0;
  double lo_ = 0, hi_ = 1, s_ = 0;
};

double InvertCdf(const double p[3], double share) {
  CdfInversion inversion(p, share);
  for (int step = 0; step < CdfInversion::kMaxSteps && !inversion.Step(); ++step) {
  }
  return inversion.s();
}

// InvertCdf(p[i], share[i]) into out[i] for the n <= 64 problems listed in
// lanes, their steps taken side by side (each its own InvertCdf's steps).

void InvertCdfs(size_t n, const uint8_t* lanes, const double (*p)[3], const double* share,
                double* out, math::VectorPath path) {
  if (path == math::VectorPath::kAvx512) {
    tree_warp_internal::InvertCdfsAvx512(n, lanes, p, share, out);
    return;
  }
  if (path == math::VectorPath::kAvx2) {
    tree_warp_internal::InvertCdfsAvx2(n, lanes, p, share, out);
    return;
  }
  CdfInversion inversion[64];
  uint8_t active[64];
  size_t count = 0;
  for (size_t j = 0; j < n; ++j) {
    inversion[j] = CdfInversion(p[lanes[j]], share[lanes[j]]);
    active[count++] = static_cast<uint8_t>(j);
  }
  for (int step = 0; step < CdfInversion::kMaxSteps && count > 0; ++step) {
    size_t still = 0;
    for (size_t c = 0; c < count; ++c) {
      if (!inversion[active[c]].Step()) active[still++] = active[c];
    }
    count = still;
  }
  for (size_t j = 0; j < n; ++j) out[lanes[j]] = inversion[j].s();
}

// The quadratic factor of a Lagrange combination sum_i w[i] L_i(s) as
// coefficients of 1, s, s^2.
void PolynomialOf(const double w[3], double p[3]) {
  const auto& k = leaf_model_internal::kBasisTable.k;
  p[0] = w[0] * k[0][0] + w[1] * k[1][0] + w[2] * k[2][0];
  p[1] = w[0] * k[0][1] + w[1] * k[1][1] + w[2] * k[2][1];
  p[2] = w[0] * k[0][2] + w[1] * k[1][2] + w[2] * k[2][2];
}

// The marginal density of s of a quadratic model in its warped coordinates
// (s, t): sum_i L_i(s) sum_j c_ij int L_j, and int_0^1 L_j is the Gauss
// weight w_j. False where it dips below zero on [0, 1].
bool MarginalOf(const LeafModel& model, double p[3]) {
  double marginal[3];
  for (int i = 0; i < 3; ++i) {
    marginal[i] = 0;
    for (int j = 0; j < 3; ++j) marginal[i] += model.c[3 * i + j] * kGaussWeight[j];
  }
  PolynomialOf(marginal, p);
  return NotNegative(p[0], p[1], p[2]);
}

// The density of t at s: sum_j L_j(t) sum_i c_ij L_i(s). False where it dips
// below zero on [0, 1] or has no mass.
bool ConditionalOf(const LeafModel& model, double s, double q[3]) {
  using leaf_model_internal::Basis;
  double basis_s[3], conditional[3];
  for (int i = 0; i < 3; ++i) basis_s[i] = Basis(i, s);
  for (int j = 0; j < 3; ++j) {
    conditional[j] = 0;
    for (int i = 0; i < 3; ++i) conditional[j] += model.c[3 * i + j] * basis_s[i];
  }
  PolynomialOf(conditional, q);
  return NotNegative(q[0], q[1], q[2]) && q[0] + q[1] / 2 + q[2] / 3 > 0;
}

// Exact marginal-then-conditional inverse CDF of a quadratic model in its
// warped coordinates (s, t); false where the quadratic dips below zero on the
// cell (the caller then splits the clamped model's sub-squares).
bool PlaceQuadratic(const LeafModel& model, double a, double b, double* s, double* t) {
  double p[3], q[3];
  if (!MarginalOf(model, p)) return false;
  *s = InvertCdf(p, a);
  if (!ConditionalOf(model, *s, q)) return false;
  *t = InvertCdf(q, b);
  return true;
}

// Leaf coordinate of the point at x of the sub-cell [x0, x0 + side] of the
// coordinates ComputeGridFactors used: those warped by a blowing-up power law
// map back through it; along a vanishing one they were the leaf's own, and
// the point is uniform in warped coordinates inside the sub-cell (the model's
// own measure there), as core/leaf_walk.cc places it.
double OnAxis(const AxisWarp& w, double x0, double side, double x) {
  if (w.power == 1) return x;
  if (DescendsWarped(w)) return Warp(w, x);
  const double s0 = Unwarp(w, x0), s1 = Unwarp(w, x0 + side);
  return std::clamp(Warp(w, s0 + (x - x0) / side * (s1 - s0)), x0, x0 + side);
}

}  // namespace

TreeWarp::TreeWarp(const CurveTree& tree)
    : tree_(tree), curve_(tree.curve()), grid_(curve_.grid()), arity_(curve_.arity()) {
  child_at_.assign(kStates * arity_, 0);
  for (int s = 0; s < kStates; ++s) {
    for (int c = 0; c < arity_; ++c) {
      const Curve::Child& ch = curve_.ChildOf(s, c);
      child_at_[s * arity_ + ch.dy * grid_ + ch.dx] = c;
    }
  }
  state_at_.assign(kStates * arity_, 0);
  for (int s = 0; s < kStates; ++s) {
    for (int at = 0; at < arity_; ++at) {
      state_at_[s * arity_ + at] = curve_.ChildOf(s, child_at_[s * arity_ + at]).state;
    }
  }
  // Depth-first over the cells down to the leaves, which come in curve
  // order; a node's child masses are differences of the running sums.
  size_t next_leaf = 0;
  std::vector<double> masses;  // per node, by position, like children_
  std::function<int32_t(int, uint64_t, int)> build = [&](int depth, uint64_t start,
                                                         int state) -> int32_t {
    if (tree.leaf_start(next_leaf) == start && tree.leaf_depth(next_leaf) == depth) {
      return -static_cast<int32_t>(next_leaf++) - 1;
    }
    const int32_t node = static_cast<int32_t>(children_.size() / arity_);
    children_.resize(children_.size() + arity_);
    masses.resize(masses.size() + arity_);
    for (int c = 0; c < arity_; ++c) {
      const Curve::Child& ch = curve_.ChildOf(state, c);
      const size_t first = next_leaf;
      const int32_t child = build(depth + 1, start + c * curve_.Span(depth + 1), ch.state);
      const int at = node * arity_ + ch.dy * grid_ + ch.dx;
      children_[at] = child;
      masses[at] = tree.mass_end(next_leaf - 1) - tree.mass_begin(first);
    }
    return node;
  };
  root_ = build(0, 0, Curve::kRootState);
  assert(next_leaf == tree.leaf_count());
  // Each node's columns and rows as stored bounds.
  const int g = grid_;
  stride_ = 2 * (g + g * g);
  const size_t nodes = children_.size() / arity_;
  splits_.resize(nodes * stride_);
  for (size_t node = 0; node < nodes; ++node) {
    const double* mass = &masses[node * arity_];
    double* out = &splits_[node * stride_];
    double column[3] = {0, 0, 0};
    for (int dy = 0; dy < g; ++dy) {
      for (int dx = 0; dx < g; ++dx) column[dx] += mass[dy * g + dx];
    }
    Bounds(column, g, out, out + g);
    for (int dx = 0; dx < g; ++dx) {
      double row[3];
      for (int dy = 0; dy < g; ++dy) row[dy] = mass[dy * g + dx];
      Bounds(row, g, out + 2 * g + 2 * g * dx, out + 2 * g + 2 * g * dx + g);
    }
  }
  // The encoding table: every chunk of levels from every orientation.
  chunk_levels_ = g == 2 ? 4 : 2;
  chunk_cells_ = g == 2 ? 16 : 9;
  const int cells = chunk_cells_ * chunk_cells_;
  encode_.assign(kStates * cells, 0);
  for (int s0 = 0; s0 < kStates; ++s0) {
    for (int y = 0; y < chunk_cells_; ++y) {
      for (int x = 0; x < chunk_cells_; ++x) {
        uint64_t digits = 0;
        int state = s0, place = chunk_cells_ / g;
        for (int level = 0; level < chunk_levels_; ++level, place /= g) {
          const int c = child_at_[state * arity_ + (y / place % g) * g + x / place % g];
          digits = digits * arity_ + c;
          state = curve_.ChildOf(state, c).state;
        }
        encode_[s0 * cells + y * chunk_cells_ + x] = digits | (uint64_t(state) << 56);
      }
    }
  }
}

template <int G>
void TreeWarp::Descend(size_t m, double* a, double* b, int32_t* ref, uint8_t* state) const {
  // One level of every point still above its leaf per round.
  constexpr int kArity = G * G, kStride = 2 * (G + G * G);
  for (bool descending = true; descending;) {
    descending = false;
    for (size_t i = 0; i < m; ++i) {
      if (ref[i] < 0) continue;
      const double* split = &splits_[ref[i] * kStride];
      const int dx = Pick(split, split + G, G, &a[i]);
      const double* rows = split + 2 * G + 2 * G * dx;
      const int dy = Pick(rows, rows + G, G, &b[i]);
      const int at = dy * G + dx;
      ref[i] = children_[ref[i] * kArity + at];
      state[i] = static_cast<uint8_t>(state_at_[state[i] * kArity + at]);
      descending |= ref[i] >= 0;
    }
  }
}

void TreeWarp::LocateMany(size_t n, const double* a_in, const double* b_in, CurveAddress* out,
                          math::VectorPath path) const {
  constexpr size_t kBatch = 64;
  double a[kBatch], b[kBatch];
  int32_t ref[kBatch];
  uint8_t state[kBatch];
  for (size_t i0 = 0; i0 < n; i0 += kBatch) {
    const size_t m = std::min(kBatch, n - i0);
    for (size_t i = 0; i < m; ++i) {
      a[i] = std::clamp(a_in[i0 + i], 0.0, kBelowOne);
      b[i] = std::clamp(b_in[i0 + i], 0.0, kBelowOne);
      ref[i] = root_;
      state[i] = Curve::kRootState;
    }
    if (grid_ == 2) {
      size_t vectored = 0;
      if (path == math::VectorPath::kAvx512) {
        vectored = tree_warp_internal::DescendGrid2Avx512(m, a, b, ref, state, splits_.data(),
                                                          children_.data(), state_at_.data());
      } else if (path == math::VectorPath::kAvx2) {
        vectored = tree_warp_internal::DescendGrid2Avx2(m, a, b, ref, state, splits_.data(),
                                                        children_.data(), state_at_.data());
      }
      Descend<2>(m - vectored, a + vectored, b + vectored, ref + vectored, state + vectored);
    } else {
      Descend<3>(m, a, b, ref, state);
    }
    // The leaves' models lie anywhere in memory: fetched a few points ahead.
    constexpr size_t kAhead = 8;
    for (size_t i = 0; i < std::min(m, kAhead); ++i) {
      __builtin_prefetch(&tree_.leaf_model(static_cast<size_t>(-ref[i] - 1)));
    }
    double x[kBatch], y[kBatch];
    uint64_t digits[kBatch];
    // Quadratic leaves: each inverse CDF over the batch side by side; the
    // others (and a quadratic that dips below zero) one at a time.
    double p[kBatch][3], s[kBatch], t[kBatch];
    uint8_t lanes[kBatch];
    size_t quadratic = 0;
    for (size_t i = 0; i < m; ++i) {
      if (i + kAhead < m) {
        __builtin_prefetch(&tree_.leaf_model(static_cast<size_t>(-ref[i + kAhead] - 1)));
      }
      const size_t l = static_cast<size_t>(-ref[i] - 1);
      if (tree_.leaf_model_kind(l) == LeafModel::Kind::kQuadratic &&
          MarginalOf(tree_.leaf_model(l), p[i])) {
        lanes[quadratic++] = static_cast<uint8_t>(i);
      }
    }
    InvertCdfs(quadratic, lanes, p, a, s, path);
    size_t conditional = 0;
    for (size_t j = 0; j < quadratic; ++j) {
      const size_t i = lanes[j];
      if (ConditionalOf(tree_.leaf_model(static_cast<size_t>(-ref[i] - 1)), s[i], p[i])) {
        lanes[conditional++] = static_cast<uint8_t>(i);
      }
    }
    InvertCdfs(conditional, lanes, p, b, t, path);
    for (size_t i = 0, j = 0; i < m; ++i) {
      const size_t l = static_cast<size_t>(-ref[i] - 1);
      if (j < conditional && lanes[j] == i) {  // PlaceInLeaf's quadratic case
        const LeafModel& model = tree_.leaf_model(l);
        x[i] = Warp(model.warp[0], s[i]);
        y[i] = Warp(model.warp[1], t[i]);
        ++j;
      } else {
        PlaceInLeaf(l, a[i], b[i], &x[i], &y[i]);
      }
    }
    DigitsInLeaf(m, x, y, state, digits, path);
    for (size_t i = 0; i < m; ++i) {
      CurveAddress& address = out[i0 + i];
      address.leaf = static_cast<uint32_t>(-ref[i] - 1);
      address.digits = digits[i];
      address.index = 0;
    }
  }
}

void TreeWarp::PlaceMany(size_t n, const CurveAddress* at, double* u, double* v,
                         double* curve_position) const {
  constexpr size_t kBatch = 64;
  uint64_t digits[kBatch], states[kBatch], cx[kBatch], cy[kBatch];
  const int levels = curve_.continuation_levels();
  const double cells = curve_.PowG(levels);
  const double digit_span = static_cast<double>(curve_.PowW(levels));
  const double curve_span = static_cast<double>(curve_.Span(0));
  double u0[kBatch], v0[kBatch], side[kBatch];
  size_t leaf = SIZE_MAX;  // the leaf whose cell is decoded
  CurveTree::Cell cell{};
  for (size_t i0 = 0; i0 < n; i0 += kBatch) {
    const size_t m = std::min(kBatch, n - i0);
    for (size_t i = 0; i < m; ++i) {
      if (at[i0 + i].leaf != leaf) leaf = at[i0 + i].leaf, cell = tree_.LeafCell(leaf);
      u0[i] = cell.u0, v0[i] = cell.v0;
      side[i] = cell.size / cells;
      digits[i] = at[i0 + i].digits;
      states[i] = static_cast<uint64_t>(cell.state);
    }
    curve_.DescendMany(digits, levels, m, states, cx, cy);
    for (size_t i = 0; i < m; ++i) {
      // The centre of the sub-cell, as LeafWalk::Continue computes it.
      u[i0 + i] = u0[i] + (static_cast<double>(cx[i]) + 0.5) * side[i];
      v[i0 + i] = v0[i] + (static_cast<double>(cy[i]) + 0.5) * side[i];
      if (curve_position == nullptr) continue;
      const size_t l = at[i0 + i].leaf;
      const double start = static_cast<double>(tree_.leaf_start(l));
      const double span = static_cast<double>(tree_.leaf_end(l) - tree_.leaf_start(l));
      const double fraction = static_cast<double>(digits[i]) / digit_span;
      curve_position[i0 + i] = CurvePosition(start + fraction * span, curve_span);
    }
  }
}

void TreeWarp::PlaceInLeaf(size_t l, double a, double b, double* x, double* y) const {
  const LeafModel& model = tree_.leaf_model(l);
  const LeafModel::Kind kind = tree_.leaf_model_kind(l);
  if (kind == LeafModel::Kind::kQuadratic) {
    double s, t;
    if (PlaceQuadratic(model, a, b, &s, &t)) {
      *x = Warp(model.warp[0], s);
      *y = Warp(model.warp[1], t);
      return;
    }
  }
  // The clamped sub-square integrals: the piecewise model's own pieces, or
  // the finest table of a leaf walk for a quadratic that dips below zero.
  const bool quadratic = kind == LeafModel::Kind::kQuadratic;
  const int n = quadratic ? static_cast<int>(curve_.PowG(curve_.table_levels())) : grid_;
  GridFactors factors;
  ComputeGridFactors(model, kind, grid_, 0, 0, 1, n, &factors);
  double column[kMaxGridCells], cells[kMaxGridCells];
  for (int i = 0; i < n; ++i) {
    column[i] = 0;
    for (int j = 0; j < n; ++j) column[i] += std::max(0.0, factors.Integral(i, j));
  }
  double total = 0;
  for (int i = 0; i < n; ++i) total += column[i];
  if (!(total > 0)) {  // the model vanishes: uniform over the leaf
    *x = a, *y = b;
    return;
  }
  const int i = Split(column, n, &a);
  for (int j = 0; j < n; ++j) cells[j] = std::max(0.0, factors.Integral(i, j));
  const int j = Split(cells, n, &b);
  const double side = 1.0 / n;
  *x = (i + a) * side, *y = (j + b) * side;
  if (quadratic) {
    *x = OnAxis(model.warp[0], i * side, side, *x);
    *y = OnAxis(model.warp[1], j * side, side, *y);
  }
}

void TreeWarp::DigitsInLeaf(size_t m, const double* x, const double* y, const uint8_t* state,
                            uint64_t* digits, math::VectorPath path) const {
  // The sub-cell's column and row among g^levels, then their base-g digits
  // a chunk at a time, from the top; each level over all m points before the
  // next, so the points' chains of table look-ups overlap.
  constexpr size_t kMax = 64;
  assert(m <= kMax);
  const int levels = curve_.continuation_levels();
  const double cells = curve_.PowG(levels);
  const uint64_t top = static_cast<uint64_t>(cells) - 1;
  const int chunks = levels / chunk_levels_, head = levels % chunk_levels_;
  if (grid_ == 2 && path == math::VectorPath::kAvx512) {
    const size_t vectored = tree_warp_internal::DigitsGrid2Avx512(
        m, x, y, state, cells, top, chunks, head, child_at_.data(), state_at_.data(),
        encode_.data(), digits);
    x += vectored, y += vectored, state += vectored, digits += vectored, m -= vectored;
  } else if (grid_ == 2 && path == math::VectorPath::kAvx2) {
    const size_t vectored = tree_warp_internal::DigitsGrid2Avx2(
        m, x, y, state, cells, top, chunks, head, child_at_.data(), state_at_.data(),
        encode_.data(), digits);
    x += vectored, y += vectored, state += vectored, digits += vectored, m -= vectored;
  }
  // Chunk values of each point's column and row, least significant first
  // (constant divisors: 16 for Hilbert, 9 for the 3x3 curves); what is left
  // are the leading levels.
  uint8_t xs[32][kMax], ys[32][kMax];
  uint64_t cx[kMax], cy[kMax];
  int s[kMax];
  for (size_t i = 0; i < m; ++i) {
    cx[i] = std::min(static_cast<uint64_t>(std::max(0.0, x[i]) * cells), top);
    cy[i] = std::min(static_cast<uint64_t>(std::max(0.0, y[i]) * cells), top);
    if (grid_ == 2) {
      for (int c = 0; c < chunks; ++c) {
        xs[c][i] = static_cast<uint8_t>(cx[i] & 15), cx[i] >>= 4;
        ys[c][i] = static_cast<uint8_t>(cy[i] & 15), cy[i] >>= 4;
      }
    } else {
      for (int c = 0; c < chunks; ++c) {
        xs[c][i] = static_cast<uint8_t>(cx[i] % 9), cx[i] /= 9;
        ys[c][i] = static_cast<uint8_t>(cy[i] % 9), cy[i] /= 9;
      }
    }
    digits[i] = 0;
    s[i] = state[i];
  }
  // The leading levels one at a time.
  uint64_t place = static_cast<uint64_t>(curve_.PowG(head));
  for (int level = 0; level < head; ++level) {
    place /= grid_;
    for (size_t i = 0; i < m; ++i) {
      const int dx = static_cast<int>(cx[i] / place % grid_);
      const int dy = static_cast<int>(cy[i] / place % grid_);
      const int c = child_at_[s[i] * arity_ + dy * grid_ + dx];
      digits[i] = digits[i] * arity_ + c;
      s[i] = curve_.ChildOf(s[i], c).state;
    }
  }
  const int cells_per_chunk = chunk_cells_ * chunk_cells_;
  const uint64_t chunk_span = curve_.PowW(chunk_levels_);
  for (int c = chunks - 1; c >= 0; --c) {
    for (size_t i = 0; i < m; ++i) {
      const uint64_t e = encode_[s[i] * cells_per_chunk + ys[c][i] * chunk_cells_ + xs[c][i]];
      digits[i] = digits[i] * chunk_span + (e & ((uint64_t{1} << 56) - 1));
      s[i] = static_cast<int>(e >> 56);
    }
  }
}

}  // namespace sfc
