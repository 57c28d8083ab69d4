// sfcsampler: the command-line interface. Builds the parser, registers the
// subcommands (commands.h, a file each) and runs the one chosen. Without
// --server every subcommand runs the sampler in-process (the embedded
// default).
#include <vector>

#include "CLI/CLI.hpp"
#include "client/cli/commands.h"

int main(int argc, char** argv) {
  CLI::App app{"sfcsampler: density-controlled low-discrepancy samples on parametric surfaces"};
  app.require_subcommand(1);
  const std::vector<sfc::Command> commands = {
      sfc::AddSampleCommand(app),   sfc::AddSampleManyCommand(app), sfc::AddPrepareCommand(app),
      sfc::AddCacheCommand(app),    sfc::AddHealthCommand(app),     sfc::AddUploadCommand(app),
      sfc::AddSurfacesCommand(app), sfc::AddInspectCommand(app),    sfc::AddEvalCommand(app),
      sfc::AddRenderCommand(app)};
  CLI11_PARSE(app, argc, argv);
  for (const sfc::Command& command : commands) {
    if (command.app->parsed()) return command.run();
  }
  return 1;  // unreachable: require_subcommand(1)
}
