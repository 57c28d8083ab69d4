// What a request says about its curve tree: the curve, the area estimator
// and the options that shape the tree (paper Sect. 5). Value types and their
// names, with no sampling code, so that the request library (request/) and
// the client can use them without the sampler.
#ifndef SFCSAMPLER_CORE_TYPES_TREE_OPTIONS_H_
#define SFCSAMPLER_CORE_TYPES_TREE_OPTIONS_H_

#include <cstdint>
#include <optional>
#include <string_view>

namespace sfc {

enum class CurveType {
  kHilbert,   // 2x2, w = 4
  kHilbert2,  // "Hilbert II": 3x3 meander from a corner to an adjacent corner, no axis of symmetry
  kPeano,     // 3x3 serpentine from a corner to the opposite corner
};

std::string_view CurveName(CurveType type);              // "hilbert", "hilbert2", "peano"
std::optional<CurveType> CurveFromName(std::string_view name);

enum class AreaEstimator {
  kTriangle,               // (a) area of f(v_{l-1}) f(v_l) f(v_{l+1}) x delta at its centroid
  kSquare,                 // (b) area of the mapped cell (two triangles) x delta at the centre
  kFirstFundamentalForm,   // (c) delta sqrt(EG - F^2) at the centre x cell area: the reference
  kQuadrature,             // (c) integrated by 3x3 Gauss-Legendre over the cell
};

std::string_view AreaEstimatorName(AreaEstimator e);  // "triangle", "square", "fff", "quadrature"
std::optional<AreaEstimator> AreaEstimatorFromName(std::string_view name);

struct CurveTreeOptions {
  CurveType curve = CurveType::kHilbert;
  AreaEstimator estimator = AreaEstimator::kFirstFundamentalForm;
  // The paper's a, in surface units; 0 means automatic: 1% of the diagonal of
  // the surface's bounding box (measured on a 17 x 17 parameter grid).
  double tolerance = 0;
  // The paper's r; 0 means the curve's deepest level (31 Hilbert, 20 3x3).
  int depth_cap = 0;
  // Scales the model-error allowance (core/curve_tree.h); > 0. Larger
  // values trade accuracy for a smaller tree.
  double rho = 1.0;
  // Budget: building or refining past this many leaves is RESOURCE_EXHAUSTED.
  // The default, 2^22 leaves at 73 bytes, is 306 MB (292 MiB).
  uint64_t max_leaves = uint64_t{1} << 22;
};

}  // namespace sfc

#endif  // SFCSAMPLER_CORE_TYPES_TREE_OPTIONS_H_
