// The local model of the mass density m = delta |f_u x f_v| that each curve
// tree leaf carries (docs/ALGORITHM.md, "A tree sized by the surface" and "Inside a
// leaf, follow the model").
//
// Two kinds, both in the leaf's own unit coordinates (x, y) in [0,1]^2:
//  - kQuadratic: the tensor-product quadratic through m at the 3 x 3
//    Gauss-Legendre nodes of the cell. Its integral over the cell is the 3 x 3
//    Gauss rule (exact for degree 5 per axis), and its integral over any
//    sub-rectangle is a closed form. It never evaluates on the cell's edges.
//    Where the area element blows up or vanishes on a parameter line (a
//    singular parameterisation, paper Sect. 5.3), the quadratic lives in
//    warped coordinates: each axis may carry a power law toward the line
//    (AxisWarp), the paper's reparameterisation u = u'^3 fitted per cell (its
//    future work, Sects. 5.3 and 6). With k = 1 / (1 + p) for a mass density
//    ~ t^p at distance t from the line, the warped density m(W(s)) W'(s) is
//    smooth, so the quadrature converges and the model follows the mass
//    piled against the line down to any sub-cell.
//  - kPiecewise: constant on each of the g x g sub-squares of the cell (g the
//    curve's grid), with the masses of the mapped sub-squares' triangles. The
//    fallback where the area element is singular and no power law fits.
// Values are stored as floats normalised so the model integrates to 1 over the
// cell: the leaf's mass lives in the tree's running sums, the model only shares
// it out.
//
// Thread-safety: plain values and pure functions.
#ifndef SFCSAMPLER_CORE_LEAF_MODEL_H_
#define SFCSAMPLER_CORE_LEAF_MODEL_H_

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "core/vector_math.h"

namespace sfc {

// 3-point Gauss-Legendre on [0,1]: nodes and weights.
inline constexpr double kGaussNode[3] = {0.5 - 0.38729833462074168852, 0.5,
                                         0.5 + 0.38729833462074168852};
inline constexpr double kGaussWeight[3] = {5.0 / 18, 8.0 / 18, 5.0 / 18};

// A power law along one axis of a leaf (x in the leaf's unit coordinates).
// The line where the mass density is singular sits at x = centre (0 or 1:
// an edge; between: a line through the cell), and x = W(s) maps [0, s_c]
// onto [0, centre] and [s_c, 1] onto [centre, 1], each piece as
// |x - centre| ~ |s - s_c|^power. The split s_c = c^(1/k) / (c^(1/k) +
// (1-c)^(1/k)) makes the warped density of a power law that is the same on
// both sides continuous. power == 1: no warp.
struct AxisWarp {
  float power;
  float centre;
};
inline constexpr AxisWarp kNoWarp = {1, 0};

inline double WarpSplit(const AxisWarp& w) {
  if (w.centre <= 0) return 0;
  if (w.centre >= 1) return 1;
  const double r = 1 / static_cast<double>(w.power);
  const double a = math::Pow(static_cast<double>(w.centre), r);
  return a / (a + math::Pow(1 - static_cast<double>(w.centre), r));
}
// W and W^-1 in two steps, for batches: with sc = WarpSplit(w), W(s) is
// WarpFrom(w, sc, s, Pow(WarpBase(w, sc, s), k)) with k = w.power, and
// W^-1(x) is UnwarpFrom(w, sc, x, Pow(UnwarpBase(w, x), 1 / k)).
inline double WarpBase(const AxisWarp& w, double sc, double s) {
  return s <= sc && sc > 0 ? 1 - s / sc : (s - sc) / (1 - sc);
}
inline double WarpFrom(const AxisWarp& w, double sc, double s, double power) {
  const double c = w.centre;
  return s <= sc && sc > 0 ? c - c * power : c + (1 - c) * power;
}
inline double UnwarpBase(const AxisWarp& w, double x) {
  const double c = w.centre;
  return x <= c && c > 0 ? (c - x) / c : (x - c) / (1 - c);
}
inline double UnwarpFrom(const AxisWarp& w, double sc, double x, double power) {
  const double c = w.centre;
  return x <= c && c > 0 ? sc * (1 - power) : sc + (1 - sc) * power;
}
// x = W(s), W'(s) and s = W^-1(x): each maps [0,1] onto itself, increasing.
inline double Warp(const AxisWarp& w, double s) {
  if (w.power == 1) return s;
  const double sc = WarpSplit(w);
  return WarpFrom(w, sc, s, math::Pow(WarpBase(w, sc, s), w.power));
}
inline double WarpSlope(const AxisWarp& w, double s) {
  if (w.power == 1) return 1;
  const double k = w.power, c = w.centre, sc = WarpSplit(w);
  if (s <= sc && sc > 0) return c * k * math::Pow(1 - s / sc, k - 1) / sc;
  return (1 - c) * k * math::Pow((s - sc) / (1 - sc), k - 1) / (1 - sc);
}
inline double Unwarp(const AxisWarp& w, double x) {
  if (w.power == 1) return x;
  const double sc = WarpSplit(w);
  return UnwarpFrom(w, sc, x, math::Pow(UnwarpBase(w, x), 1 / static_cast<double>(w.power)));
}

// Whether the walk descends a leaf's curve in the warped coordinate of this
// axis: where its power law blows up (power > 1) the mass piled against the
// line is even there, and the curve's cells become thin strips along the line,
// as the line's thin bands need. Where it vanishes (power < 1) the warp would
// widen the cells beside the line instead; the curve stays in leaf
// coordinates and only the model is warped.
inline bool DescendsWarped(const AxisWarp& w) { return w.power > 1; }

// Where the warped density is evaluated for the node s: s itself, except at
// the split of a line through the cell (the middle node, for a line at the
// cell's centre), where the line itself is no point to evaluate at: the
// warped density, nearly constant there, is taken at least 2^-20 beside the
// line in both s and x.
inline double WarpNode(const AxisWarp& w, double s) {
  if (w.power == 1 || w.centre <= 0 || w.centre >= 1) return s;
  const double split = WarpSplit(w);
  if (!(std::fabs(s - split) < 0x1p-20)) return s;
  return std::max(split + 0x1p-20, Unwarp(w, w.centre + 0x1p-20));
}

struct LeafModel {
  enum class Kind : uint8_t { kQuadratic = 0, kPiecewise = 1 };
  // kQuadratic: c[3 i + j] is the model at node (kGaussNode[i], kGaussNode[j]).
  // kPiecewise: c[i * grid + j] is the density on sub-square (i, j) of the
  // grid x grid split (i along x).
  float c[9];
  // The power law of each axis (0: x, 1: y) for kQuadratic; the nodes of c
  // are at W(kGaussNode).
  AxisWarp warp[2];

  // Normalised model of the given kind from raw values (densities at nodes,
  // in warped coordinates, or sub-square masses): scaled so the model
  // integrates to 1. REQUIRES: the values are finite and >= 0 with a positive
  // integral; else a uniform model.
  static LeafModel FromQuadratic(const double values[9], const AxisWarp* warp = nullptr);
  static LeafModel FromPiecewise(const double masses[9], int grid);
  static LeafModel Uniform();
};

// The integral of the model over [x0, x1] x [y0, y1] (inside [0,1]^2). For
// kQuadratic it may be negative where the quadratic dips below zero; callers
// clamp.
double ModelIntegral(const LeafModel& model, LeafModel::Kind kind, int grid, double x0, double x1,
                     double y0, double y1);

namespace leaf_model_internal {

// The Lagrange basis polynomials on the Gauss nodes, L_i(x) = k[i][0] +
// k[i][1] x + k[i][2] x^2, computed at compile time (the same bits as at run
// time: IEEE arithmetic, no contraction).
struct BasisTable {
  double k[3][3];
};
constexpr double Basis(int i, double x) {
  double p = 1;
  for (int k = 0; k < 3; ++k) {
    if (k != i) p *= (x - kGaussNode[k]) / (kGaussNode[i] - kGaussNode[k]);
  }
  return p;
}
constexpr double BasisLead(int i) {  // the x^2 coefficient
  double p = 1;
  for (int k = 0; k < 3; ++k) {
    if (k != i) p /= kGaussNode[i] - kGaussNode[k];
  }
  return p;
}
constexpr BasisTable MakeBasisTable() {
  BasisTable table{};
  for (int i = 0; i < 3; ++i) {
    const double l0 = Basis(i, 0), l1 = Basis(i, 1), lead = BasisLead(i);
    table.k[i][0] = l0;
    table.k[i][2] = lead;
    table.k[i][1] = l1 - l0 - lead;
  }
  return table;
}
inline constexpr BasisTable kBasisTable = MakeBasisTable();

// int_a^b L_i = d L_i(mid) + lead d^3 / 12, exact for a quadratic and free of
// the cancellation of b^3 - a^3 on tiny intervals.
inline void BasisIntegrals(double a, double b, double out[3]) {
  const double d = b - a, mid = (a + b) / 2, d3 = d * d * d / 12;
  for (int i = 0; i < 3; ++i) {
    const double* k = kBasisTable.k[i];
    out[i] = d * (k[0] + mid * (k[1] + mid * k[2])) + k[2] * d3;
  }
}

}  // namespace leaf_model_internal

// Largest n of GridFactors: cells per side of a walk's table.
inline constexpr int kMaxGridCells = 32;

// The integrals of the model over the n x n sub-squares of the square
// [x0, x0 + side] x [y0, y0 + side], in the coordinates the walk descends in
// (DescendsWarped): warped along an axis whose power law blows up, the
// leaf's own along the others. The model is a sum of products of 1D
// functions (the Lagrange basis of the quadratic, the pieces' indicators of
// the piecewise model), so ComputeGridFactors does the 1D integrals along
// each axis once, and Integral(i, j) (sub-square i along x, j along y) is 3
// products; a quadratic may give negative values where it dips below zero.
// Along an axis the walk descends in (every axis but one whose power law
// vanishes) it also keeps the integrals over each sub-square's lower half,
// for the slope of the mass across it (LowerX, LowerY).
struct GridFactors {
  int factors;                       // 3 (quadratic) or the piecewise grid
  bool halves[2];                    // whether x_low (axis 0) and row_low (axis 1) are filled
  double x[3][kMaxGridCells];        // x[a][i]: factor a's integral over column i
  double row[3][kMaxGridCells];      // row[a][j] = sum_b c[a, b] (factor b's integral over row j)
  double x_low[3][kMaxGridCells];    // the same over the lower half of column i
  double row_low[3][kMaxGridCells];  // and of row j
  double Integral(int i, int j) const {
    double sum = 0;
    for (int a = 0; a < factors; ++a) sum += x[a][i] * row[a][j];
    return sum;
  }
  // The integrals over the lower half of sub-square (i, j) along x and along
  // y. REQUIRES: halves[0], halves[1] respectively.
  double LowerX(int i, int j) const {
    double sum = 0;
    for (int a = 0; a < factors; ++a) sum += x_low[a][i] * row[a][j];
    return sum;
  }
  double LowerY(int i, int j) const {
    double sum = 0;
    for (int a = 0; a < factors; ++a) sum += x[a][i] * row_low[a][j];
    return sum;
  }
};
// `grid` is the piecewise model's grid (the curve's). REQUIRES: 1 <= n <= kMaxGridCells.
void ComputeGridFactors(const LeafModel& model, LeafModel::Kind kind, int grid, double x0,
                        double y0, double side, int n, GridFactors* out);

// ComputeGridFactors in two steps where the model is a quadratic with no
// power law below 1 (HasQuadraticGridFactors): the 1D integrals of the three
// basis functions along each axis (the same for every such model, so a
// caller may keep those of a square it meets often, such as a leaf's own),
// then the model's combination of them. The same bits.
struct AxisFactors {
  int n;
  double full[3][kMaxGridCells];  // full[b][k]: basis b's integral over cell k of n
  double low[3][kMaxGridCells];   // the same over its lower half
};
// The integrals over the n cells of [origin, origin + side] and their
// lower halves. REQUIRES: 1 <= n <= kMaxGridCells.
void ComputeAxisFactors(double origin, double side, int n, AxisFactors* out);
bool HasQuadraticGridFactors(const LeafModel& model, LeafModel::Kind kind);
// ComputeGridFactors(model, kQuadratic, ., x0, y0, side, n, out) from x and
// y, ComputeAxisFactors of (x0, side, n) and (y0, side, n).
// REQUIRES: HasQuadraticGridFactors(model, kQuadratic).
void QuadraticGridFactors(const LeafModel& model, const AxisFactors& x, const AxisFactors& y,
                          GridFactors* out);

// The quadratic through unnormalised node values at (x, y) of the leaf's own
// coordinates (no warp); also outside the nodes, as an extrapolation.
inline double QuadraticAt(const double values[9], double x, double y) {
  using leaf_model_internal::Basis;
  double sum = 0;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) sum += values[3 * i + j] * Basis(i, x) * Basis(j, y);
  }
  return sum;
}

// The same for unnormalised quadratic node values (double precision) in the
// coordinates warped by `warp` (null: none), used by the tree's error test.
double QuadraticIntegral(const double values[9], double x0, double x1, double y0, double y1,
                         const AxisWarp* warp = nullptr);

}  // namespace sfc

#endif  // SFCSAMPLER_CORE_LEAF_MODEL_H_
