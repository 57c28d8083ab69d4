// Sample-anchored density discrepancy over parameter boxes (issue 19,
// docs/ALGORITHM.md "Evaluation protocol"): D = sup over boxes R of
// |points in R / N - int_R delta dA / int delta dA|, with box corners at the
// points' own coordinates, at random points and on a grid graded toward the
// singular lines, and each box's reference mass integrated on the box itself.
//
// The reference shares nothing with the curve tree: only the surface's jet
// (f_u, f_v; second derivatives for curvature densities) and the density.
// The boxes' corners cut both axes into cells; every cell is integrated by
// Gauss-Legendre, and the cells are graded toward the singular lines so that
// an area element like |t|^(e-1) (e = 1/4 .. 3) converges:
//  - around every line, breakpoints at distances 4^-k / 16 down to 1e-11;
//  - any cell [d1, d2] of distances to its nearest line with d2 > 4 d1 is
//    split geometrically, so every cell off a line spans a factor <= 4;
//  - a cell that touches a line is mapped by x = line + h w^12, which turns
//    |t|^(e-1) into w^(12 e - 1) (a polynomial for e = 1/4, 1/3, 2, 3).
// So a box's mass is exact to quadrature precision for any corner position;
// the tests check it against exact areas and against the independent
// closed-form superellipsoid quadrature (evaluation/superellipsoid_exact.h).
//
// Thread-safety: pure functions.
#ifndef SFCSAMPLER_EVALUATION_BOX_DISCREPANCY_H_
#define SFCSAMPLER_EVALUATION_BOX_DISCREPANCY_H_

#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/density.h"
#include "core/surface.h"
#include "evaluation/discrepancy.h"

namespace sfc {

// Lines of the unit parameter square where delta dA blows up or vanishes:
// u = u[i] (all v) and v = v[j] (all u).
struct SingularLines {
  std::vector<double> u, v;
};

// Lines found by probing: at each candidate c in {k/1024, k/12, k/10} of
// either axis, and at 7 positions along it, the local exponents
// log(m(c + 1e-7) / m(c + 1e-5)) / log(1e-2) and the same for 1e-5 .. 1e-3
// of m = delta |f_u x f_v| on each side; a candidate is a line when both
// exceed 0.1 in size and agree within a factor 2 at 6 of the 7 positions on
// one side (a smooth non-vanishing m gives ~1e-3; a line 1e-3 away shows on
// the coarse scale only). Lines elsewhere are not found. Cost: ~1e5
// evaluations.
absl::StatusOr<SingularLines> DetectSingularLines(const Surface& surface, const Density& density);

// The breakpoints of one axis and the masses of the cells they make.
class GradedBoxMeasure {
 public:
  // Cuts each axis at 0, 1, the lines, the grading around the lines, a
  // uniform grid of `background` cells and the given extra breakpoints (any
  // values in [0,1]), and integrates every cell. Errors: INVALID_ARGUMENT if
  // delta dA is not finite or negative at a quadrature node.
  static absl::StatusOr<GradedBoxMeasure> Build(const Surface& surface, const Density& density,
                                                const SingularLines& lines,
                                                std::vector<double> u_breaks,
                                                std::vector<double> v_breaks, int background = 128);

  // Sorted breakpoints, first 0, last 1.
  const std::vector<double>& u() const { return u_; }
  const std::vector<double>& v() const { return v_; }
  // int of delta dA over [u[i0], u[i1]) x [v[j0], v[j1]), i0 <= i1, j0 <= j1.
  double Mass(size_t i0, size_t i1, size_t j0, size_t j1) const;
  double total() const { return Mass(0, u_.size() - 1, 0, v_.size() - 1); }
  // Index of a breakpoint equal to x (REQUIRES: x was a breakpoint).
  size_t UIndex(double x) const;
  size_t VIndex(double x) const;

 private:
  std::vector<double> u_, v_;
  std::vector<double> prefix_;  // (u_.size()) x (v_.size()): mass of [0,u_i) x [0,v_j)
};

struct BoxDiscrepancyOptions {
  int sample_corners = 256;  // per axis: coordinates of the points at evenly spaced ranks,
                             // each both as x and just above x (open and closed boxes)
  int random_corners = 128;  // per axis, uniform
  int background = 128;      // uniform grid of cells per axis
  int random_boxes = 200000; // boxes with all four sides at random breakpoints
  uint64_t seed = 1;         // for the random corners and boxes (std::mt19937_64)
};

struct BoxDiscrepancy {
  double d = 0;                                 // the sup found
  double u0 = 0, u1 = 0, v0 = 0, v1 = 0;        // the box that attains it
  double point_fraction = 0, mass_fraction = 0; // its two sides
  size_t boxes = 0;                             // boxes tried
};

// Boxes tried: every box with a corner of the square as one corner and a
// grid point as the opposite one (4 x grid points), and `random_boxes` boxes
// with random grid sides. Cost: the cells' quadrature, ~(6.5 K)^2 evaluations
// for K cells an axis, plus O(N log K + K^2).
absl::StatusOr<BoxDiscrepancy> SampleAnchoredBoxDiscrepancy(
    const Surface& surface, const Density& density, const SingularLines& lines,
    const std::vector<Point2>& uv, const BoxDiscrepancyOptions& options = {});

}  // namespace sfc

#endif  // SFCSAMPLER_EVALUATION_BOX_DISCREPANCY_H_
