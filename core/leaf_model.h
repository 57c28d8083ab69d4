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

// The integrals over the grid x grid sub-squares of the square
// [x0, x0 + side] x [y0, y0 + side]: out[i * grid + j] for the sub-square i
// along x, j along y. Shares the 1D integrals between sub-squares.
void SubSquareIntegrals(const LeafModel& model, LeafModel::Kind kind, int grid, double x0,
                        double y0, double side, double out[9]);

// The same for unnormalised quadratic node values (double precision), used by
// the tree's error test.
double QuadraticIntegral(const double values[9], double x0, double x1, double y0, double y1);

}  // namespace sfc

#endif  // SFCSAMPLER_CORE_LEAF_MODEL_H_
