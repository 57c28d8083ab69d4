// The local model of the mass density m = delta |f_u x f_v| that each curve
// tree leaf carries (ALGORITHM.md, "A tree sized by the surface" and "Inside a
// leaf, follow the model").
//
// Two kinds, both in the leaf's own unit coordinates (x, y) in [0,1]^2:
//  - kQuadratic: the tensor-product quadratic through m at the 3 x 3
//    Gauss-Legendre nodes of the cell. Its integral over the cell is the 3 x 3
//    Gauss rule (exact for degree 5 per axis), and its integral over any
//    sub-rectangle is a closed form. It never evaluates on the cell's edges.
//  - kPiecewise: constant on each of the g x g sub-squares of the cell (g the
//    curve's grid), with the masses of the mapped sub-squares' triangles. Used
//    where the area element blows up (a singular parameterisation, paper
//    Sect. 5.3): there the quadrature does not converge, the mapped triangles do.
// Values are stored as floats normalised so the model integrates to 1 over the
// cell: the leaf's mass lives in the tree's running sums, the model only shares
// it out.
//
// Thread-safety: plain values and pure functions.
#ifndef SFCSAMPLER_CORE_LEAF_MODEL_H_
#define SFCSAMPLER_CORE_LEAF_MODEL_H_

#include <cstdint>

namespace sfc {

// 3-point Gauss-Legendre on [0,1]: nodes and weights.
inline constexpr double kGaussNode[3] = {0.5 - 0.38729833462074168852, 0.5,
                                         0.5 + 0.38729833462074168852};
inline constexpr double kGaussWeight[3] = {5.0 / 18, 8.0 / 18, 5.0 / 18};

struct LeafModel {
  enum class Kind : uint8_t { kQuadratic = 0, kPiecewise = 1 };
  // kQuadratic: c[3 i + j] is the model at node (kGaussNode[i], kGaussNode[j]).
  // kPiecewise: c[i * grid + j] is the density on sub-square (i, j) of the
  // grid x grid split (i along x).
  float c[9];

  // Normalised model of the given kind from raw values (densities at nodes,
  // or sub-square masses): scaled so the model integrates to 1. REQUIRES: the
  // values are finite and >= 0 with a positive integral; else a uniform model.
  static LeafModel FromQuadratic(const double values[9]);
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

void PiecewiseSubSquareIntegrals(const LeafModel& model, int grid, double x0, double y0,
                                 double side, double out[9]);

}  // namespace leaf_model_internal

// The integrals over the grid x grid sub-squares of the square
// [x0, x0 + side] x [y0, y0 + side]: out[i * grid + j] for the sub-square i
// along x, j along y. Shares the 1D integrals, and each y row of the
// quadratic, between sub-squares. Inline: the sampler's descent calls it once
// per model level. REQUIRES: grid is 2 or 3 (the curves' grids).
template <int kGrid>
inline void SubSquareIntegralsOnGrid(const LeafModel& model, LeafModel::Kind kind, double x0,
                                     double y0, double side, double out[9]) {
  if (kind == LeafModel::Kind::kPiecewise) {
    leaf_model_internal::PiecewiseSubSquareIntegrals(model, kGrid, x0, y0, side, out);
    return;
  }
  // The 1D integrals of the basis over the kGrid cells along y (k < kGrid)
  // and along x (k >= kGrid): BasisIntegrals' arithmetic, written as loops
  // over the cells so the compiler pairs their divisions in vector registers.
  const double step = side / kGrid;
  constexpr int kCells = 2 * kGrid;
  double a[kCells], b[kCells], d[kCells], mid[kCells], d3[kCells], integral[kCells][3];
  for (int k = 0; k < kGrid; ++k) {
    a[k] = y0 + k * step, b[k] = y0 + (k + 1) * step;
    a[kGrid + k] = x0 + k * step, b[kGrid + k] = x0 + (k + 1) * step;
  }
  for (int k = 0; k < kCells; ++k) {
    d[k] = b[k] - a[k];
    mid[k] = (a[k] + b[k]) / 2;
    d3[k] = d[k] * d[k] * d[k] / 12;
  }
  for (int k = 0; k < kCells; ++k) {
    for (int i = 0; i < 3; ++i) {
      const double* c = leaf_model_internal::kBasisTable.k[i];
      integral[k][i] = d[k] * (c[0] + mid[k] * (c[1] + mid[k] * c[2])) + c[2] * d3[k];
    }
  }
  double row[kGrid][3];  // row[j][a] = sum_b c[3a + b] int_{y-cell j} L_b
  for (int j = 0; j < kGrid; ++j) {
    const double* iy = integral[j];
    for (int a = 0; a < 3; ++a) {
      row[j][a] = model.c[3 * a] * iy[0] + model.c[3 * a + 1] * iy[1] + model.c[3 * a + 2] * iy[2];
    }
  }
  for (int i = 0; i < kGrid; ++i) {
    const double* ix = integral[kGrid + i];
    for (int j = 0; j < kGrid; ++j) {
      double sum = 0;
      for (int a = 0; a < 3; ++a) sum += ix[a] * row[j][a];
      out[i * kGrid + j] = sum;
    }
  }
}

inline void SubSquareIntegrals(const LeafModel& model, LeafModel::Kind kind, int grid, double x0,
                               double y0, double side, double out[9]) {
  if (grid == 2) {
    SubSquareIntegralsOnGrid<2>(model, kind, x0, y0, side, out);
  } else {
    SubSquareIntegralsOnGrid<3>(model, kind, x0, y0, side, out);
  }
}

// The same for unnormalised quadratic node values (double precision), used by
// the tree's error test.
double QuadraticIntegral(const double values[9], double x0, double x1, double y0, double y1);

}  // namespace sfc

#endif  // SFCSAMPLER_CORE_LEAF_MODEL_H_
