#include "client/cli/model_read_flags.h"

#include "absl/strings/str_cat.h"
#include "base/subprocess.h"

namespace sfc {

void AddModelReadFlags(CLI::App* cmd, ModelReadFlags* flags) {
  cmd->add_option("--model-check-program", flags->model_check_program,
                  "in process: read each CAD file in this program, a process of its own, so one "
                  "that crashes or loops the CAD kernel fails alone (auto = sfcsampler-model-check "
                  "installed with this program, if any; none = in this process)")
      ->capture_default_str();
  cmd->add_option("--model-parse-seconds", flags->model_parse_seconds,
                  "in process: CPU seconds one model's read may take (a CAD file's check program "
                  "is stopped at this limit, and at 4x it of wall-clock time)")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
}

absl::Status ApplyModelReadFlags(const ModelReadFlags& flags, SampleSourceOptions* options) {
  const absl::StatusOr<std::string> program =
      ResolveProgramFlag(flags.model_check_program, "sfcsampler-model-check");
  if (!program.ok()) {
    return absl::Status(program.status().code(),
                        absl::StrCat("--model-check-program: ", program.status().message()));
  }
  options->model_check_program = *program;
  options->model_parse_seconds = flags.model_parse_seconds;
  return absl::OkStatus();
}

}  // namespace sfc
