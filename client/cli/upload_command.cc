// `sfcsampler upload`: sends model files to an sfcsampler-server once (only
// those it lacks) and prints their wire specs FORMAT:sha256=HASH, one a
// line, for any later job to name; --server only.
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "client/cli/commands.h"
#include "client/cli/connection_flags.h"
#include "client/cli/exit_status.h"
#include "client/cli/sample_source.h"

namespace sfc {
namespace {

struct UploadFlags {
  std::vector<std::string> specs;  // FORMAT:FILE
  ConnectionFlags connection;
};

int RunUpload(const UploadFlags& flags) {
  const std::unique_ptr<SampleSource> source = OpenSampleSource(flags.connection);
  for (const std::string& spec : flags.specs) {
    auto wire = source->UploadModel(spec);
    if (!wire.ok()) return Fail(wire.status());
    std::printf("%s\n", wire->c_str());
  }
  return 0;
}

}  // namespace

Command AddUploadCommand(CLI::App& app) {
  auto flags = std::make_shared<UploadFlags>();
  CLI::App* upload = app.add_subcommand(
      "upload",
      "send model files to the server once (only if it lacks them) and print FORMAT:sha256=HASH "
      "specs that any job can name; sample and prepare with --server do this by themselves");
  upload->add_option("models", flags->specs, "FORMAT:FILE, FORMAT one of step iges nurbs obj ply")
      ->required();
  AddConnectionFlags(upload, &flags->connection);
  return {upload, [flags] { return RunUpload(*flags); }};
}

}  // namespace sfc
