#include "kinds/cad/model_check.h"

#include <signal.h>
#include <string.h>

#include <algorithm>
#include <vector>

#include "absl/strings/numbers.h"
#include "absl/strings/str_format.h"
#include "absl/strings/strip.h"
#include "base/echo.h"
#include "base/subprocess.h"
#include "engine/loaded_models.h"

namespace sfc {

absl::StatusOr<std::string> ReadModelInSubprocess(const ModelCheckLimits& limits,
                                                  ModelFormat format, const std::string& bytes,
                                                  const std::string& name,
                                                  const std::function<absl::Status()>& check) {
  const double wall_seconds = limits.cpu_seconds > 0 ? std::max(10.0, 4 * limits.cpu_seconds) : 0;
  const std::vector<std::string> argv = {
      limits.program, std::string(ModelFormatName(format)), name,
      absl::StrFormat("%d", static_cast<uint64_t>(limits.cpu_seconds + 0.999)),
      absl::StrFormat("%d", limits.memory_bytes), absl::StrFormat("%g", limits.yield_seconds)};
  // The answer's size: the BRep of a model is about the size of its file,
  // at most a few times it.
  const size_t max_output = std::max<size_t>(size_t{16} << 20, 8 * bytes.size());
  absl::StatusOr<SubprocessResult> run =
      RunSubprocess(argv, bytes, max_output, wall_seconds, check);
  if (!run.ok()) return run.status();
  const size_t end_of_line = run->output.find('\n');
  absl::string_view line = absl::StripTrailingAsciiWhitespace(
      absl::string_view(run->output).substr(0, std::min(end_of_line, size_t{2048})));
  if (run->exited && run->exit_code == 0 && absl::StartsWith(line, "ok ")) {
    size_t size = 0;
    if (end_of_line == std::string::npos || !absl::SimpleAtoi(line.substr(3), &size) ||
        run->output_clipped || run->output.size() - end_of_line - 1 != size) {
      return absl::InternalError(absl::StrFormat(
          "the model check %s sent a malformed answer (%d bytes)", Echo(limits.program),
          run->output.size()));
    }
    return run->output.substr(end_of_line + 1);
  }
  if (run->exited && run->exit_code == 1) {
    // "CODE MESSAGE": the loader's own refusal.
    const size_t space = line.find(' ');
    int code = 0;
    if (space != absl::string_view::npos && absl::SimpleAtoi(line.substr(0, space), &code) &&
        code > 0 && code <= static_cast<int>(absl::StatusCode::kUnauthenticated)) {
      return absl::Status(static_cast<absl::StatusCode>(code), line.substr(space + 1));
    }
  }
  if (run->timed_out) {
    return absl::ResourceExhaustedError(absl::StrFormat(
        "reading the model took more than %g s and was stopped (the CAD kernel made no progress "
        "it reports); simplify or re-export the model",
        wall_seconds));
  }
  if (!run->exited && run->signal == SIGXCPU) {
    return ParseBudgetSpent(limits.cpu_seconds);
  }
  if (!run->exited) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "the CAD kernel crashed reading this model (signal %d, %s; memory limit %d bytes); it was "
        "read in a process of its own, so nothing else was affected; fix or re-export the model",
        run->signal, strsignal(run->signal), limits.memory_bytes));
  }
  return absl::InternalError(absl::StrFormat("the model check %s ended with status %d: %s",
                                             Echo(limits.program), run->exit_code, Echo(line)));
}

}  // namespace sfc
