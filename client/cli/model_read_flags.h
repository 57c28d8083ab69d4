// The flags that bound how the CLI reads model files in process (sample,
// inspect, sample-many): each CAD file is read by sfcsampler-model-check in
// a process of its own, as the server reads uploads, so a file that crashes,
// loops or exhausts the CAD kernel fails alone and within its CPU budget;
// the same model, and so the same bytes, as a server makes of the file.
#ifndef SFCSAMPLER_CLIENT_CLI_MODEL_READ_FLAGS_H_
#define SFCSAMPLER_CLIENT_CLI_MODEL_READ_FLAGS_H_

#include <string>

#include "CLI/CLI.hpp"
#include "absl/status/status.h"
#include "client/cli/sample_source.h"
#include "request/model_files.h"

namespace sfc {

struct ModelReadFlags {
  // "auto" = sfcsampler-model-check installed with this program, else read
  // in this process; "none" = in this process; or a path.
  std::string model_check_program = "auto";
  // CPU seconds one model's read may take (request/model_files.h).
  double model_parse_seconds = kDefaultModelParseSeconds;
};

// Adds --model-check-program and --model-parse-seconds to `cmd`; `flags`
// must outlive parsing.
void AddModelReadFlags(CLI::App* cmd, ModelReadFlags* flags);

// `options` with the program resolved and the budget set; FAILED_PRECONDITION
// naming the flag when a named program cannot be run.
absl::Status ApplyModelReadFlags(const ModelReadFlags& flags, SampleSourceOptions* options);

}  // namespace sfc

#endif  // SFCSAMPLER_CLIENT_CLI_MODEL_READ_FLAGS_H_
