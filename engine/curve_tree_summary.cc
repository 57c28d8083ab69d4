#include "engine/curve_tree_summary.h"

namespace sfc {
namespace {

TreeSummary::Cell ToCell(const DepthCapHit& hit) {
  TreeSummary::Cell cell;
  cell.test = hit.test == DepthCapHit::Test::kGeometry ? "flatness"
              : hit.test == DepthCapHit::Test::kMass   ? "mass"
                                                       : "singular";
  cell.u0 = hit.u0, cell.v0 = hit.v0, cell.size = hit.size;
  cell.measured = hit.measured, cell.limit = hit.limit;
  return cell;
}

}  // namespace

void FillTreeSummary(const CurveTree& tree, TreeSummary* out) {
  const PrecisionReport& precision = tree.precision();
  out->min_depth = tree.min_depth();
  out->max_depth = tree.max_depth();
  out->tolerance = tree.options().tolerance;
  out->flatness_capped_leaves = precision.geometry_capped_leaves;
  out->mass_capped_leaves = precision.mass_capped_leaves;
  out->warnings.clear();
  for (const DepthCapHit& hit : precision.worst) out->warnings.push_back(ToCell(hit));
  out->error_samples = precision.error_samples;
  out->unresolved_error_samples = precision.unresolved_error_samples;
  out->hidden_share = precision.hidden_share;
  out->singular_leaves = precision.singular_leaves;
  out->warped_leaves = precision.warped_leaves;
  out->small_failing_leaves = precision.small_failing_leaves;
  out->singular.clear();
  for (const DepthCapHit& hit : precision.singular) out->singular.push_back(ToCell(hit));
}

}  // namespace sfc
