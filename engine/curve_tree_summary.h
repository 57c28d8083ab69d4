// How a CurveTree (core/curve_tree.h: the tree over the parameter square of
// catalogue and expression surfaces) describes itself in a TreeSummary
// (request/tree_summary.h), through its public accessors. TypedTree<CurveTree>
// (engine/tree_source.h) calls it. Thread-safety: a pure function.
#ifndef SFCSAMPLER_ENGINE_CURVE_TREE_SUMMARY_H_
#define SFCSAMPLER_ENGINE_CURVE_TREE_SUMMARY_H_

#include "core/curve_tree.h"
#include "request/tree_summary.h"

namespace sfc {

// Fills the surface fields of `out`: depths, the tolerance used and the
// precision report (depth-cap hits, model error, singular leaves).
void FillTreeSummary(const CurveTree& tree, TreeSummary* out);

}  // namespace sfc

#endif  // SFCSAMPLER_ENGINE_CURVE_TREE_SUMMARY_H_
