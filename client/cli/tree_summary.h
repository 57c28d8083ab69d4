// What the CLI says about a curve tree it sampled or prepared: a summary
// independent of where the tree was made, filled from a PreparedTree in
// process (in_process_sample_source.cc) or from the wire's TreeInfo
// (server_sample_source.cc), and printed on stderr by PrintTreeSummary with
// the same text either way.
#ifndef SFCSAMPLER_CLIENT_CLI_TREE_SUMMARY_H_
#define SFCSAMPLER_CLIENT_CLI_TREE_SUMMARY_H_

#include <cstdint>
#include <string>
#include <vector>

namespace sfc {

struct TreeSummary {
  // A leaf's parameter cell [u0, u0+size) x [v0, v0+size) and the test that
  // flagged it: "flatness" or "mass" (depth cap) or "singular".
  struct Cell {
    std::string test;
    double u0 = 0, v0 = 0, size = 0;
    double measured = 0, limit = 0;
  };

  std::string kind;  // "surface", "mesh" or "model"
  std::string key_with_grade;
  int grade = 0;
  bool cache_hit = false;  // the exact tree was cached
  bool refined = false;    // made by refining a cached coarser tree
  uint64_t leaves = 0, bytes = 0;
  // A "surface" tree's only; zero for meshes and models.
  int min_depth = 0, max_depth = 0;
  double tolerance = 0;
  double error_samples = 0, unresolved_error_samples = 0;
  uint64_t warped_leaves = 0, singular_leaves = 0;
  uint64_t flatness_capped_leaves = 0, mass_capped_leaves = 0;
  std::vector<Cell> singular;  // the finest singular leaves
  std::vector<Cell> warnings;  // the worst depth-cap hits
  // How long the tree took to be ready, when known (< 0: not, as on a
  // server's stream): the server's own Prepare time if
  // `seconds_from_server`, else the wait for an in-process build.
  double seconds = -1;
  bool seconds_from_server = false;
};

// What the summary printout leaves out: -q drops the summary, the progress
// lines and the note on fitted power laws, --no-warnings the warnings too
// (which -q keeps: they say the samples' density is only approximate
// somewhere).
struct Verbosity {
  bool quiet = false;
  bool no_warnings = false;
};

// Prints the summary, its notes and depth-cap warnings, and its time, on
// stderr, as `verbosity` allows.
void PrintTreeSummary(const TreeSummary& tree, const Verbosity& verbosity = {});

}  // namespace sfc

#endif  // SFCSAMPLER_CLIENT_CLI_TREE_SUMMARY_H_
