// Runs a program in a process of its own, for work that may crash, loop or
// exhaust memory (a hostile model file in a library that cannot be made
// safe): whatever it does costs that process, not this one.
//
// The program gets `input` on its standard input (from an in-memory file,
// so nothing can block on a pipe), its standard output is collected up to
// `max_output` bytes (the rest is read and dropped), its standard error goes
// nowhere. The caller's
// `check` is asked every few milliseconds while the program runs; when it
// says to stop, or `wall_seconds` pass, the program is killed (SIGKILL) and
// the result says why. Limits on the program's own CPU time and memory are
// the program's to set (setrlimit) from its arguments.
//
// Thread-safety: thread-safe (each call has its own process and files).
#ifndef SFCSAMPLER_BASE_SUBPROCESS_H_
#define SFCSAMPLER_BASE_SUBPROCESS_H_

#include <functional>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"

namespace sfc {

struct SubprocessResult {
  bool exited = false;  // ended by exit(); else by a signal
  int exit_code = 0;    // when exited
  int signal = 0;       // when not exited
  bool timed_out = false;  // killed at wall_seconds
  std::string output;   // standard output, at most max_output bytes
  bool output_clipped = false;  // it wrote more than max_output
};

// Runs `argv` (argv[0]: the program's path). INTERNAL when it cannot be
// started; the check's status when the check stopped it (the program is
// killed and reaped first). `wall_seconds` <= 0: no wall-clock limit.
absl::StatusOr<SubprocessResult> RunSubprocess(const std::vector<std::string>& argv,
                                               absl::string_view input, size_t max_output,
                                               double wall_seconds,
                                               const std::function<absl::Status()>& check);

// The path of the helper program `name` installed with this one: next to
// this process's executable, or in ../server/ beside it (a build tree, where
// the CLI is in client/ and the server's helpers in server/); "" when neither
// is executable.
std::string FindSiblingProgram(const std::string& name);

// A helper program named by a flag: "none" is "", "auto" is
// FindSiblingProgram(name) ("" when it is not installed), anything else a path
// that must be executable (FAILED_PRECONDITION naming it otherwise).
absl::StatusOr<std::string> ResolveProgramFlag(const std::string& flag, const std::string& name);

}  // namespace sfc

#endif  // SFCSAMPLER_BASE_SUBPROCESS_H_
