// What every model-loader fuzz target checks (issue 21): the loader returns;
// a refusal is INVALID_ARGUMENT or RESOURCE_EXHAUSTED with a message of at
// most 1 KB holding only printable ASCII (input echoes are escaped and
// clipped); a load stops within its time budget. Any other outcome traps.
#ifndef SFCSAMPLER_FUZZ_MODEL_FUZZ_H_
#define SFCSAMPLER_FUZZ_MODEL_FUZZ_H_

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <string>

#include "absl/status/status.h"

namespace sfc::fuzz {

[[noreturn]] inline void Fail(const char* what, const absl::Status& status) {
  std::fprintf(stderr, "fuzz: %s\n  %s\n", what, status.ToString().substr(0, 2000).c_str());
  __builtin_trap();
}

inline void CheckRefusal(const absl::Status& status) {
  if (status.ok()) return;
  const auto code = status.code();
  if (code != absl::StatusCode::kInvalidArgument && code != absl::StatusCode::kResourceExhausted &&
      code != absl::StatusCode::kDeadlineExceeded) {
    Fail("a bad model is not INVALID_ARGUMENT or RESOURCE_EXHAUSTED", status);
  }
  if (status.message().size() > 1024) Fail("an error message longer than 1 KB", status);
  for (const char c : status.message()) {
    if (c < 0x20 || c > 0x7e) Fail("an error message with an unescaped byte", status);
  }
}

// With SFC_FUZZ_LAST_INPUT=FILE set, each input is written there before it
// runs: the OpenCASCADE targets leave SEGV to the kernel's handler, and an
// input that kills the process anyway (a stack overflow) is not saved by
// libFuzzer.
inline void RememberInput(const uint8_t* data, size_t size) {
  static const char* path = std::getenv("SFC_FUZZ_LAST_INPUT");
  if (path == nullptr) return;
  if (FILE* f = std::fopen(path, "wb")) {
    std::fwrite(data, 1, size, f);
    std::fclose(f);
  }
}

// A check that stops a load after `seconds` of wall time (DEADLINE_EXCEEDED).
inline std::function<absl::Status()> Budget(double seconds) {
  const auto end = std::chrono::steady_clock::now() +
                   std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                       std::chrono::duration<double>(seconds));
  return [end] {
    return std::chrono::steady_clock::now() > end
               ? absl::DeadlineExceededError("the fuzz input's time budget is spent")
               : absl::OkStatus();
  };
}

}  // namespace sfc::fuzz

#endif  // SFCSAMPLER_FUZZ_MODEL_FUZZ_H_
