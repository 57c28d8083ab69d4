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
#include "request/tree_count.h"

namespace sfc {
namespace {

struct PrepareFlags {
  RequestFlags request;
  ConnectionFlags connection;
};

int RunPrepare(const PrepareFlags& flags) {
  auto request = ToSampleRequest(flags.request);
  if (!request.ok()) return Fail(request.status());
  auto tree_count = ResolveTreeCount(*request);
  if (!tree_count.ok()) return Fail(tree_count.status());
  auto source = OpenSampleSource(flags.connection);
  if (!source.ok()) return Fail(source.status());
  Progress progress(true);
  auto tree = (*source)->Prepare(request->tree, *tree_count, &progress);
  progress.Done();
  if (!tree.ok()) return Fail(tree.status());
  PrintTreeSummary(*tree);
  std::printf("%s\n", tree->tree.key_with_grade.c_str());
  return 0;
}

}  // namespace

Command AddPrepareCommand(CLI::App& app) {
  auto flags = std::make_shared<PrepareFlags>();
  CLI::App* prepare =
      app.add_subcommand("prepare", "build (warm) a curve tree and print its key and statistics");
  AddTreeFlags(prepare, &flags->request);
  prepare->add_option("--count,-n", flags->request.count, "size the tree for this many samples")
      ->capture_default_str()
      ->check(kWholeNumber);
  AddConnectionFlags(prepare, &flags->connection);
  return {prepare, [flags] { return RunPrepare(*flags); }};
}

}  // namespace sfc
