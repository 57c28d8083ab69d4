// `sfcsampler upload`: sends model files to an sfcsampler-server once (only
// those it lacks) and prints their wire specs FORMAT:sha256=HASH, one a
// line, for any later job to name; --server required.
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "absl/strings/str_format.h"
#include "client/cli/commands.h"
#include "client/cli/connection_flags.h"
#include "client/cli/exit_status.h"
#include "request/model_spec.h"

namespace sfc {
namespace {

struct UploadFlags {
  std::vector<std::string> specs;  // FORMAT:FILE
  ConnectionFlags connection;
};

int RunUpload(const UploadFlags& flags) {
  auto client = ConnectClient(flags.connection);
  if (!client.ok()) return Fail(client.status());
  for (const std::string& spec : flags.specs) {
    auto parsed = ParseModelSpec(spec);
    if (!parsed.ok()) return Fail(parsed.status());
    if (!parsed->has_value()) {
      return Fail(absl::InvalidArgumentError(
          absl::StrFormat("\"%s\" names no model file; write FORMAT:FILE with FORMAT %s", spec,
                          ModelFormatList())));
    }
    auto wire = (*client)->EnsureModel(spec);
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
  AddConnectionFlags(upload, &flags->connection, ServerFlag::kRequired);
  return {upload, [flags] { return RunUpload(*flags); }};
}

}  // namespace sfc
