// Discrepancy estimators for the evaluation protocol (paper Sects. 4-5;
// docs/ALGORITHM.md "Evaluation protocol"): D = sup over a family of test shapes
// of |points inside / N - measure of the shape|.
//
// Each estimator takes the sup over a finite family, so it is a lower bound of
// the true sup over the whole family; each says which shapes it tries, its
// cost, and where it is exact. Thread-safety: pure functions.
#ifndef SFCSAMPLER_EVALUATION_DISCREPANCY_H_
#define SFCSAMPLER_EVALUATION_DISCREPANCY_H_

#include <cstdint>
#include <functional>
#include <vector>

#include "core/types/vec3.h"

namespace sfc {

struct Point2 {
  double x, y;
};

// Star discrepancy: anchored boxes [0,a) x [0,b), counted open and closed.
// The corners a, b are taken from the points' own coordinates (every one when
// N <= max_corners, otherwise max_corners of them at evenly spaced ranks) and
// 1. With every coordinate this is the exact star discrepancy (the sup is
// attained at such corners). Cost O(N log N + K^2 log N), K = corners per axis.
double StarDiscrepancy(const std::vector<Point2>& points, int max_corners = 512);

// Quarter discs x^2 + y^2 < r^2 centred on the origin corner, r in (0, sqrt 2],
// with the exact area of their intersection with the unit square. Exact:
// O(N log N), checking each point's radius from both sides.
double QuarterDiscDiscrepancy(const std::vector<Point2>& points);

// Triangles x/a + y/b < 1 anchored at the origin corner, for a and b on a
// grid of `grid` values each in (0, 2.5] (a grid of (k + 1/2)/grid * 2.5),
// with the exact area of their intersection with the square. Exact over that
// family. Cost O(grid * N log grid).
double TriangleDiscrepancy(const std::vector<Point2>& points, int grid = 256);
// Area of {x/a + y/b < 1, x, y >= 0} intersected with the unit square.
double AnchoredTriangleArea(double a, double b);
// Area of the quarter disc of radius r intersected with the unit square.
double QuarterDiscArea(double r);

// Least-squares slope of log d against log n (the protocol's convergence
// rate). REQUIRES: n.size() == d.size() >= 2, all values > 0.
double LogLogSlope(const std::vector<double>& n, const std::vector<double>& d);

// Spherical triangles on the unit sphere: `triangles` triangles with vertices
// uniform on the sphere (from `seed`), area by Girard's theorem (the spherical
// excess, computed as in Van Oosterom and Strackee 1983). Points must be unit
// vectors. Exact over that family. Cost O(N * triangles).
double SphericalTriangleDiscrepancy(const std::vector<Vec3>& points, int triangles = 128,
                                    uint64_t seed = 1);

// Density discrepancy on any surface, over parameter rectangles:
// sup |points inside / N - int_R delta dA / int delta dA|. `cell_mass(u0, v0,
// h)` integrates delta dA over a parameter cell (callers use a quadrature).
// Rectangles: every anchored [0,i/G) x [0,j/G) on a G = `grid` grid, and every
// rectangle of the coarser grid of G/8 cells a side. Points are binned to the
// G grid, so this is exact for rectangles of that grid. Cost O(N + G^2 cell
// integrals + (G/8)^4 / 4).
double ParameterRectDiscrepancy(const std::vector<Point2>& uv,
                                const std::function<double(double, double, double)>& cell_mass,
                                int grid = 256);

}  // namespace sfc

#endif  // SFCSAMPLER_EVALUATION_DISCREPANCY_H_
