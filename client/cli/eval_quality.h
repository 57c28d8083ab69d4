// `sfcsampler eval`'s quality report (issue 19, evaluation/quality.h): the
// flags, and the run that prints the report and writes it to the output
// folder. Thread-safety: call from one thread.
#ifndef SFCSAMPLER_CLIENT_CLI_EVAL_QUALITY_H_
#define SFCSAMPLER_CLIENT_CLI_EVAL_QUALITY_H_

#include <string>
#include <vector>

#include "CLI/CLI.hpp"
#include "evaluation/quality.h"

namespace sfc {

struct EvalQualityFlags {
  // protocol (the paper's Tables 1-2) and/or quality (issue 19's report)
  std::vector<std::string> sections = {"protocol", "quality"};
  std::vector<std::string> quality_sections;  // empty: all
  std::vector<uint64_t> seeds = {1, 2, 3};
  std::string step_sphere, mesh_sphere;
};

void AddEvalQualityFlags(CLI::App* eval, EvalQualityFlags* flags);

bool WantsSection(const EvalQualityFlags& flags, const std::string& section);

// Runs the report with sets from `source`, prints it to stdout and writes
// quality.md into `out_dir`. Returns the process exit code (0 also when
// checks FAIL: the report is the result).
int RunEvalQuality(const EvalQualityFlags& flags, bool full, const std::string& out_dir,
                   const QualitySource& source);

}  // namespace sfc

#endif  // SFCSAMPLER_CLIENT_CLI_EVAL_QUALITY_H_
