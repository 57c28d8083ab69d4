#include "client/cli/tree_summary.h"

#include <cstdio>

#include "core/curve_tree.h"

namespace sfc {
namespace {

void PrintCells(const std::vector<TreeSummary::Cell>& cells) {
  for (const TreeSummary::Cell& w : cells) {
    std::fprintf(stderr, "  cell u in [%.9g, %.9g], v in [%.9g, %.9g]\n", w.u0, w.u0 + w.size, w.v0,
                 w.v0 + w.size);
  }
}

// The summary, notes and warnings, without the time.
void PrintFacts(const TreeSummary& t, const Verbosity& verbosity) {
  if (!verbosity.quiet && (t.kind == "mesh" || t.kind == "model")) {
    std::fprintf(stderr, "%s tree %s (%s): %llu leaves, %llu bytes\n", t.kind.c_str(),
                 t.key_with_grade.c_str(), t.cache_hit ? "cache hit" : "built",
                 static_cast<unsigned long long>(t.leaves),
                 static_cast<unsigned long long>(t.bytes));
    return;
  }
  if (!verbosity.quiet) {
    std::fprintf(stderr, "tree %s (%s): %llu leaves, depth %d..%d, %llu bytes, tolerance %.6g\n",
                 t.key_with_grade.c_str(),
                 t.cache_hit ? "cache hit"
                 : t.refined ? "refined from cache"
                             : "built",
                 static_cast<unsigned long long>(t.leaves), t.min_depth, t.max_depth,
                 static_cast<unsigned long long>(t.bytes), t.tolerance);
    std::fprintf(stderr,
                 "precision: model error %.3g samples in all (%.3g where the tests wanted more) at "
                 "N = 2^%d\n",
                 t.error_samples, t.unresolved_error_samples, t.grade);
    if (t.hidden_share > 0) {
      std::fprintf(stderr,
                   "precision: features narrower than the tree's probes were found and followed; "
                   "its leaves may still hide %.3g of the mass (refused above %.3g)\n",
                   t.hidden_share, CurveTree::kHiddenShare);
    }
  }
  if (verbosity.no_warnings) return;
  // A note, not a warning: the power laws follow the mass (-q drops it).
  if (t.warped_leaves > 0 && !verbosity.quiet) {
    std::fprintf(
        stderr,
        "note: the parameterisation is singular (the area element blows up or vanishes on "
        "parameter lines, paper Sect. 5.3); %llu leaves beside those lines follow a fitted "
        "power law%s\n",
        static_cast<unsigned long long>(t.warped_leaves), t.singular_leaves > 0 ? "" : ". Finest:");
    if (t.singular_leaves == 0) PrintCells(t.singular);
  }
  if (t.singular_leaves > 0) {
    std::fprintf(
        stderr,
        "warning: the area element is not smooth (it blows up, vanishes or creases; paper Sect. "
        "5.3) in %llu leaves that no power law fits; their masses come from mapped "
        "sub-triangles, samples are spread evenly inside their sub-squares, and such leaves "
        "are split until each carries a small fraction of a sample. Finest:\n",
        static_cast<unsigned long long>(t.singular_leaves));
    PrintCells(t.singular);
  }
  if (t.flatness_capped_leaves || t.mass_capped_leaves) {
    std::fprintf(stderr,
                 "warning: the depth cap stopped splits the tests still wanted (paper Sect. 5.3): "
                 "%llu leaves for flatness, %llu for mass\n",
                 static_cast<unsigned long long>(t.flatness_capped_leaves),
                 static_cast<unsigned long long>(t.mass_capped_leaves));
    for (const TreeSummary::Cell& w : t.warnings) {
      std::fprintf(
          stderr,
          "  %s test at cell u in [%.9g, %.9g], v in [%.9g, %.9g]: %.6g vs limit %.6g (x%.3g)\n",
          w.test.c_str(), w.u0, w.u0 + w.size, w.v0, w.v0 + w.size, w.measured, w.limit,
          w.measured / w.limit);
    }
  }
}

}  // namespace

void PrintTreeSummary(const TreeReport& report, const Verbosity& verbosity) {
  PrintFacts(report.tree, verbosity);
  if (report.seconds < 0 || verbosity.quiet) return;
  std::fprintf(stderr, "%s in %.3f s\n", report.seconds_from_server ? "prepared" : "tree ready",
               report.seconds);
}

}  // namespace sfc
