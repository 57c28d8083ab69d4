// Internal to cad/: boxes of a B-spline or Bezier face over parameter
// sub-boxes from the control points of the sub-patch. The face's Bezier
// patches (one a knot span, from the kernel's conversion, which inserts knots
// to full multiplicity) are kept as homogeneous control points; a sub-box's
// part of each patch it meets is cut out by de Casteljau's algorithm, in u
// and then in v (Farin, Curves and Surfaces for CAGD, 5th ed. 2002, Sect. 4.6
// and 14.3; a rational patch in homogeneous coordinates, Sect. 13.2), and a
// rational patch lies in the convex hull of its control points because its
// weights are positive (Piegl and Tiller, The NURBS Book, 2nd ed. 1997, Sect.
// 4.4). Arithmetic only: the same bits on every CPU. No OpenCASCADE type.
//
// Immutable after construction; thread-safe.
#ifndef SFCSAMPLER_CAD_INTERNAL_SPAN_HULL_H_
#define SFCSAMPLER_CAD_INTERNAL_SPAN_HULL_H_

#include <optional>
#include <vector>

#include "core/surface.h"

namespace sfc::cad {

class SpanHull {
 public:
  // `u_knots` (count nu + 1) and `v_knots` (nv + 1) bound the patches' spans,
  // increasing; patch (a, b) spans [u_knots[a], u_knots[a + 1]] x [v_knots[b],
  // v_knots[b + 1]] and has pu x pv control points, point (i, j) at
  // points[(((a * nv + b) * pu + i) * pv + j) * 4 + k]: w x, w y, w z, w for
  // k = 0..3 (w > 0).
  SpanHull(std::vector<double> u_knots, std::vector<double> v_knots, int pu, int pv,
           std::vector<double> points);

  // The box of the control points of the parts of the patches over
  // [a0, a1] x [b0, b1] (native parameters, each widened by 1e-12 of its
  // span for the mapping's rounding), or nullopt when the sub-box leaves the
  // knots' range by more than 1e-9 of it or a weight is not positive. The
  // caller widens it for the kernel's rounding.
  std::optional<Box3> Bound(double a0, double a1, double b0, double b1) const;

 private:
  std::vector<double> u_knots_, v_knots_;
  int pu_, pv_;
  std::vector<double> points_;
};

}  // namespace sfc::cad

#endif  // SFCSAMPLER_CAD_INTERNAL_SPAN_HULL_H_
