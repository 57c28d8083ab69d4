// `sfcsampler inspect`: lists the faces of CAD models read in process (the
// files are on this machine): index as in the face column, type, trimmed
// area, parameter box, orientation, trim, and the order the curve visits
// them.
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "client/cli/commands.h"
#include "client/cli/exit_status.h"
#include "client/cli/in_process_sample_source.h"
#include "client/cli/model_read_flags.h"

namespace sfc {
namespace {

int RunInspect(const std::vector<std::string>& specs, const ModelReadFlags& read) {
  SampleSourceOptions options;
  if (absl::Status applied = ApplyModelReadFlags(read, &options); !applied.ok())
    return Fail(applied);
  InProcessSampleSource local(options);
  for (const std::string& spec : specs) {
    auto table = local.engine().DescribeModel(spec);
    if (!table.ok()) return Fail(table.status());
    std::printf("%s", table->c_str());
  }
  return 0;
}

}  // namespace

Command AddInspectCommand(CLI::App& app) {
  auto specs = std::make_shared<std::vector<std::string>>();
  auto read = std::make_shared<ModelReadFlags>();
  CLI::App* inspect = app.add_subcommand(
      "inspect",
      "list a CAD model's faces (index as in the face column, type, trimmed area, "
      "parameter box, orientation, trim) and the order the curve visits them");
  inspect->add_option("models", *specs, "step:FILE, iges:FILE or nurbs:FILE")->required();
  AddModelReadFlags(inspect, read.get());
  return {inspect, [specs, read] { return RunInspect(*specs, *read); }};
}

}  // namespace sfc
