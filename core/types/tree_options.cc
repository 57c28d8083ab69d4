#include "core/types/tree_options.h"

namespace sfc {

std::string_view CurveName(CurveType type) {
  switch (type) {
    case CurveType::kHilbert:
      return "hilbert";
    case CurveType::kHilbert2:
      return "hilbert2";
    case CurveType::kPeano:
      return "peano";
  }
  return "hilbert";
}

std::optional<CurveType> CurveFromName(std::string_view name) {
  for (CurveType t : {CurveType::kHilbert, CurveType::kHilbert2, CurveType::kPeano}) {
    if (name == CurveName(t)) return t;
  }
  return std::nullopt;
}

std::string_view AreaEstimatorName(AreaEstimator e) {
  switch (e) {
    case AreaEstimator::kTriangle:
      return "triangle";
    case AreaEstimator::kSquare:
      return "square";
    case AreaEstimator::kFirstFundamentalForm:
      return "fff";
    case AreaEstimator::kQuadrature:
      return "quadrature";
  }
  return "fff";
}

std::optional<AreaEstimator> AreaEstimatorFromName(std::string_view name) {
  for (AreaEstimator e : {AreaEstimator::kTriangle, AreaEstimator::kSquare,
                          AreaEstimator::kFirstFundamentalForm, AreaEstimator::kQuadrature}) {
    if (name == AreaEstimatorName(e)) return e;
  }
  return std::nullopt;
}

}  // namespace sfc
