// What the CLI says about a tree it sampled or prepared: its summary
// (request/tree_summary.h), made by the engine in process
// (in_process_sample_source.cc) or read from the wire's TreeInfo
// (server_sample_source.cc), printed on stderr by PrintTreeSummary with the
// same text either way.
#ifndef SFCSAMPLER_CLIENT_CLI_TREE_SUMMARY_H_
#define SFCSAMPLER_CLIENT_CLI_TREE_SUMMARY_H_

#include "request/tree_summary.h"

namespace sfc {

// A tree's summary (request/tree_summary.h, the same in process and from a
// server) and how long the tree took to be ready, when known (< 0: not, as
// on a server's stream): the server's own Prepare time if
// `seconds_from_server`, else the wait for an in-process build.
struct TreeReport {
  TreeSummary tree;
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
void PrintTreeSummary(const TreeReport& report, const Verbosity& verbosity = {});

}  // namespace sfc

#endif  // SFCSAMPLER_CLIENT_CLI_TREE_SUMMARY_H_
