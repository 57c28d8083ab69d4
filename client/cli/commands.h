// The subcommands of sfcsampler, one file each (*_command.cc, and
// sample_many.cc): each Add...Command adds its subcommand and flags to the
// app and returns a Command whose `run`, called after parsing when the
// subcommand was chosen, does the work and returns the process exit code.
// The subcommands that sample (sample, sample-many, prepare, eval, render's
// samples) run in process or against --server through a SampleSource
// (sample_source.h); cache, health and upload need --server (the parser
// requires it) and take the client (ConnectClient, connection_flags.h);
// inspect and render's curve tree ask the in-process engine.
#ifndef SFCSAMPLER_CLIENT_CLI_COMMANDS_H_
#define SFCSAMPLER_CLIENT_CLI_COMMANDS_H_

#include <functional>

#include "CLI/CLI.hpp"

namespace sfc {

struct Command {
  CLI::App* app;             // the subcommand's node in the parser
  std::function<int()> run;  // its flags are bound to what `run` reads
};

Command AddSampleCommand(CLI::App& app);
Command AddSampleManyCommand(CLI::App& app);
Command AddPrepareCommand(CLI::App& app);
Command AddCacheCommand(CLI::App& app);
Command AddHealthCommand(CLI::App& app);
Command AddUploadCommand(CLI::App& app);
Command AddSurfacesCommand(CLI::App& app);
Command AddInspectCommand(CLI::App& app);
Command AddEvalCommand(CLI::App& app);
Command AddRenderCommand(CLI::App& app);

}  // namespace sfc

#endif  // SFCSAMPLER_CLIENT_CLI_COMMANDS_H_
