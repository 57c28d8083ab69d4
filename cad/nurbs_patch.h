// Our plain NURBS patch format (docs/NURBS_FORMAT.md): a text file giving the
// degrees, the full (clamped) knot vectors and the control points with their
// weights. Parsing and validation only; cad/load.cc turns a patch into the
// kernel's B-spline surface. Pure functions; thread-safe.
#ifndef SFCSAMPLER_CAD_NURBS_PATCH_H_
#define SFCSAMPLER_CAD_NURBS_PATCH_H_

#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"

namespace sfc::cad {

// Largest degree accepted (the kernel's Geom_BSplineSurface::MaxDegree()).
inline constexpr int kMaxNurbsDegree = 25;

struct NurbsPatch {
  int degree_u = 0, degree_v = 0;
  int count_u = 0, count_v = 0;  // control points along u and along v
  // Full knot vectors, repeated knots written out: count + degree + 1 each.
  std::vector<double> knots_u, knots_v;
  // Control point (i, j), i < count_u, j < count_v, at [i * count_v + j]:
  // x, y, z and the weight w > 0.
  struct Pole {
    double x, y, z, w;
  };
  std::vector<Pole> poles;
};

// Parses and validates a patch. Errors are INVALID_ARGUMENT naming `name`
// and the line: a missing or unknown keyword, a bad number, NaN or infinite
// values, degree outside [1, kMaxNurbsDegree], knot count != count + degree + 1,
// decreasing knots, an interior multiplicity above the degree, ends that are
// not clamped (multiplicity degree + 1), an empty parameter range, a weight
// that is not positive, a wrong number of control points.
absl::StatusOr<NurbsPatch> ParseNurbsPatch(absl::string_view text, absl::string_view name);

}  // namespace sfc::cad

#endif  // SFCSAMPLER_CAD_NURBS_PATCH_H_
