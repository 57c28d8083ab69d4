#include "python/bindings/tree_summary_dict.h"

#include <vector>

namespace py = pybind11;

namespace sfc::python {
namespace {

py::list CellList(const std::vector<TreeSummary::Cell>& cells) {
  py::list out;
  for (const TreeSummary::Cell& cell : cells) {
    py::dict d;
    d["test"] = cell.test;
    d["u0"] = cell.u0, d["v0"] = cell.v0, d["size"] = cell.size;
    d["measured"] = cell.measured, d["limit"] = cell.limit;
    out.append(d);
  }
  return out;
}

}  // namespace

py::dict TreeSummaryDict(const TreeSummary& s) {
  py::dict d;
  d["kind"] = s.kind;
  d["key"] = s.key;
  d["key_with_grade"] = s.key_with_grade;
  d["grade"] = s.grade;
  d["cache_hit"] = s.cache_hit;
  d["refined"] = s.refined;
  d["leaves"] = s.leaves;
  d["bytes"] = s.bytes;
  d["min_depth"] = s.min_depth;
  d["max_depth"] = s.max_depth;
  d["tolerance"] = s.tolerance;
  d["flatness_capped_leaves"] = s.flatness_capped_leaves;
  d["mass_capped_leaves"] = s.mass_capped_leaves;
  d["warnings"] = CellList(s.warnings);
  d["canonical"] = s.canonical;
  d["error_samples"] = s.error_samples;
  d["unresolved_error_samples"] = s.unresolved_error_samples;
  d["hidden_share"] = s.hidden_share;
  d["singular_leaves"] = s.singular_leaves;
  d["singular"] = CellList(s.singular);
  d["small_failing_leaves"] = s.small_failing_leaves;
  d["warped_leaves"] = s.warped_leaves;
  return d;
}

}  // namespace sfc::python
