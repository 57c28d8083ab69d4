// `sfcsampler prepare`: builds (warms) the curve tree a later `sample` would
// use, in process or on --server, prints its summary on stderr and its key
// (with grade) on stdout.
#include <cstdio>
#include <memory>

#include "client/cli/commands.h"
#include "client/cli/connection_flags.h"
#include "client/cli/exit_status.h"
#include "request/request_flags.h"
#include "client/cli/sample_source.h"

namespace sfc {
namespace {

struct PrepareFlags {
  RequestFlags request;
  ConnectionFlags connection;
};

int RunPrepare(const PrepareFlags& flags) {
  auto spec = ToTreeSpec(flags.request);
  if (!spec.ok()) return Fail(spec.status());
  const std::unique_ptr<SampleSource> source = OpenSampleSource(flags.connection);
  Progress progress(true);
  auto tree = source->Prepare(
      *spec, flags.request.tree_count ? flags.request.tree_count : flags.request.count, &progress);
  progress.Done();
  if (!tree.ok()) return Fail(tree.status());
  PrintTreeSummary(*tree);
  std::printf("%s\n", tree->key_with_grade.c_str());
  return 0;
}

}  // namespace

Command AddPrepareCommand(CLI::App& app) {
  auto flags = std::make_shared<PrepareFlags>();
  CLI::App* prepare =
      app.add_subcommand("prepare", "build (warm) a curve tree and print its key and statistics");
  AddTreeFlags(prepare, &flags->request);
  prepare->add_option("--count,-n", flags->request.count, "size the tree for this many samples")
      ->capture_default_str();
  AddConnectionFlags(prepare, &flags->connection);
  return {prepare, [flags] { return RunPrepare(*flags); }};
}

}  // namespace sfc
