// What is known about a prepared tree, of any kind: the one summary every
// front door shows. The engine fills it (engine/sampling_engine.h
// SummarizeTree: the request's fields, then the tree's own through
// AnyTree::FillSummary, so each kind of tree describes itself); proto/convert.h
// maps it to the wire's TreeInfo and back; the CLI prints it
// (client/cli/tree_summary.h) and Python hands it over as a dict with the
// same names (python/bindings/sampling.cc). The fields are TreeInfo's, with
// its names and meaning (proto/sfcsampler/v1/sampler.proto).
// Thread-safety: a plain value.
#ifndef SFCSAMPLER_REQUEST_TREE_SUMMARY_H_
#define SFCSAMPLER_REQUEST_TREE_SUMMARY_H_

#include <cstdint>
#include <string>
#include <vector>

namespace sfc {

struct TreeSummary {
  // A leaf's parameter cell [u0, u0+size) x [v0, v0+size) and the test that
  // flagged it: "flatness" or "mass" (the depth cap stopped it) or
  // "singular" (measured and limit 0).
  struct Cell {
    std::string test;
    double u0 = 0, v0 = 0, size = 0;
    double measured = 0, limit = 0;  // distance (surface units) or mass; the limit
  };

  // Of every tree, filled from the request: its kind's name ("surface",
  // "mesh", "model"), its key, and whether it came from a cache.
  std::string kind;
  std::string key;  // stable hash of the TreeSpec, 16 hex digits
  std::string key_with_grade;
  std::string canonical;   // the canonical text that was hashed
  int grade = 0;           // fine enough for up to 2^grade samples
  bool cache_hit = false;  // the exact tree was cached
  bool refined = false;    // made by refining a cached coarser tree

  // Of every tree, filled by the tree: its size (what it costs a cache,
  // which for a mesh or a model includes what it keeps alive).
  uint64_t leaves = 0, bytes = 0;

  // A "surface" tree's (a CurveTree over the parameter square) only; zero
  // and empty for other kinds.
  int min_depth = 0, max_depth = 0;
  double tolerance = 0;  // the tolerance used (resolved if 0 was asked)
  // Leaves the depth cap stopped, for the flatness and for the error test,
  // and the worst of them (at most 8, largest measured/limit first).
  uint64_t flatness_capped_leaves = 0, mass_capped_leaves = 0;
  std::vector<Cell> warnings;
  // The leaf models' mass error summed over all leaves, in samples of the
  // grade, and the part of it in leaves the tests still wanted to split.
  double error_samples = 0, unresolved_error_samples = 0;
  // What the leaves may still hide of the total mass in features narrower
  // than the tree's probes (found by interval bounds, confirmed by a probe;
  // docs/ALGORITHM.md, "Features narrower than the probes"); the build is
  // refused above CurveTree::kHiddenShare. 0 for densities that cannot bound
  // themselves.
  double hidden_share = 0;
  // Leaves with a singular area element that no edge power law fits, those
  // fitted by one (warped), the finest of either (at most 8), and leaves the
  // error test wanted to split that carry too few samples to matter.
  uint64_t singular_leaves = 0, warped_leaves = 0, small_failing_leaves = 0;
  std::vector<Cell> singular;
};

}  // namespace sfc

#endif  // SFCSAMPLER_REQUEST_TREE_SUMMARY_H_
