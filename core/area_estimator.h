// Estimators of a curve vertex's share of int delta dS (paper Sect. 3,
// estimators (a), (b), (c); docs/ALGORITHM.md step 2), plus a cell quadrature.
//
// All functions are pure and thread-safe. Errors: InvalidArgument when the
// surface is not finite or the density is negative or not finite at a point
// the estimator evaluates; the message names the point.
#ifndef SFCSAMPLER_CORE_AREA_ESTIMATOR_H_
#define SFCSAMPLER_CORE_AREA_ESTIMATOR_H_

#include <optional>
#include <string_view>

#include "absl/status/statusor.h"
#include "core/density.h"
#include "core/surface.h"
#include "core/types/tree_options.h"

namespace sfc {

// INVALID_ARGUMENT saying the surface is not finite at (u, v) and what to fix.
absl::Status SurfaceNotFiniteError(double u, double v);

// The sizes (a bounding box's diagonal) whose area elements double precision
// holds: |f_u x f_v| and the first fundamental form's E G - F^2 take the
// fourth power of a size, which overflows past about 1e77 and loses its
// digits to subnormals below about 1e-77.
inline constexpr double kSmallestSize = 1e-75;
inline constexpr double kLargestSize = 1e75;
// The diagonal of the box [lo, hi], without overflow or underflow in its
// squares.
double Diagonal(const Vec3& lo, const Vec3& hi);
// OK when `diagonal` is 0 (left to the caller's "no area" message) or in
// [kSmallestSize, kLargestSize]; else INVALID_ARGUMENT naming `what` (the
// surface, a mesh) and saying to scale it.
absl::Status CheckSize(std::string_view what, double diagonal);

// The density's view of the point (u, v) whose jet is `jet`, with the area
// element there in *area_element (|f_u x f_v|; infinite on a singular line).
// The normal and curvatures are filled only when `curvature` is set.
SurfacePoint PointFromJet(const SurfaceJet& jet, double u, double v, bool curvature,
                          double* area_element);

// INVALID_ARGUMENT unless delta (the density at (u, v)) is finite and >= 0.
absl::Status CheckDensityValue(double delta, double u, double v);

// The mass density m = delta |f_u x f_v| at the grid points (us[i], vs[j]),
// i < nu, j < nv: out[i * nv + j], through Surface::JetGrid (jets of the
// order the density needs). +infinity where the point, its area element or
// delta is not finite (a pole or singular line); delta is not checked for
// sign (CheckDensityValue). REQUIRES: nu * nv <= kMassDensityGridPoints.
inline constexpr int kMassDensityGridPoints = 81;
void MassDensityGrid(const Surface& surface, const Density& density, const double* us, int nu,
                     const double* vs, int nv, double* out);

// delta and the area element at one parameter point.
struct DensityAt {
  Vec3 p;
  double delta = 0;
  double area_element = 0;
};
absl::StatusOr<DensityAt> EvaluateDensity(const Surface& surface, const Density& density, double u,
                                          double v);

// int over the cell [u0,u0+h] x [v0,v0+h] of delta dS, estimated by (b), (c)
// or the quadrature. For (c) the cell area h^2 is the paper's w^(kmax - k)
// normalisation. REQUIRES: estimator != kTriangle.
absl::StatusOr<double> CellMass(const Surface& surface, const Density& density,
                                AreaEstimator estimator, double u0, double v0, double h);

// CellMass of the n x n cells of side h with lower-left corner (u0, v0):
// masses[i * n + j] for the cell [u0 + i h, ..) x [v0 + j h, ..). Estimator
// (c) evaluates the centres with Surface::JetGrid. REQUIRES: n <= 3.
absl::Status CellMassesOnGrid(const Surface& surface, const Density& density,
                              AreaEstimator estimator, double u0, double v0, double h, int n,
                              double* masses);

// Estimator (a) for the vertex `cur` with curve neighbours `prev` and `next`
// (parameter points): the area of the mapped triangle times delta at the
// parameter centroid. Zero when the three mapped vertices are collinear.
absl::StatusOr<double> TriangleMass(const Surface& surface, const Density& density, double prev_u,
                                    double prev_v, double cur_u, double cur_v, double next_u,
                                    double next_v);

}  // namespace sfc

#endif  // SFCSAMPLER_CORE_AREA_ESTIMATOR_H_
