// sfcsampler-model-check FORMAT NAME CPU_SECONDS MEMORY_BYTES YIELD_SECONDS < FILE
//
// Reads a CAD model (step, iges or nurbs) from standard input with
// cad::ReadToBrep (every check cad::Load makes), in a process of its own with
// the given limits (0: none) on its CPU time (RLIMIT_CPU; SIGXCPU past it)
// and address space (RLIMIT_AS). After YIELD_SECONDS of CPU (0: never) it
// drops to the idle scheduling class (SCHED_IDLE): a long read yields the
// CPU to every other process, the short reads of other clients' models
// first (engine/loaded_models.h). It dies with its parent. Prints one line
// and exits:
//   0  "ok BYTES", then BYTES bytes: the model read, as cad::ReadToBrep's
//      binary BRep, which the server loads with cad::LoadBrep;
//   1  "CODE MESSAGE"               the read refused it (an absl status code);
//   2  "usage ..."                  bad arguments.
// A crash or a loop inside OpenCASCADE ends this process, not the server
// (kinds/cad/model_check.h runs it; docs/MODELS.md says why).
#include <sched.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/time.h>

#include <algorithm>
#include <cstdio>
#include <exception>
#include <iostream>
#include <iterator>
#include <new>
#include <string>

#include "absl/strings/numbers.h"
#include "base/echo.h"
#include "cad/load.h"

namespace {

void Limit(int resource, uint64_t soft, uint64_t hard) {
  if (soft == 0) return;
  rlimit limit{static_cast<rlim_t>(soft), static_cast<rlim_t>(hard)};
  setrlimit(resource, &limit);
}

// One line of at most 1 KB (the loader's messages already escape the input).
int Print(int code, std::string line) {
  for (char& c : line) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  std::printf("%s\n", sfc::ClipMessage(line, 1024).c_str());
  std::fflush(stdout);
  return code;
}

}  // namespace

// SIGPROF, once YIELD_SECONDS of CPU are spent: this thread, the reader's,
// to the idle class. (sched_setscheduler is a plain system call.)
void YieldTheCpu(int) {
  sched_param param{};
  sched_setscheduler(0, SCHED_IDLE, &param);
}

int main(int argc, char** argv) {
  uint64_t cpu_seconds = 0, memory_bytes = 0;
  double yield_seconds = 0;
  if (argc != 6 || !absl::SimpleAtoi(argv[3], &cpu_seconds) ||
      !absl::SimpleAtoi(argv[4], &memory_bytes) || !absl::SimpleAtod(argv[5], &yield_seconds) ||
      !(yield_seconds >= 0)) {
    return Print(2, "usage: sfcsampler-model-check FORMAT NAME CPU_SECONDS MEMORY_BYTES "
                    "YIELD_SECONDS < FILE");
  }
  if (yield_seconds > 0) {
    signal(SIGPROF, YieldTheCpu);
    const auto micros = static_cast<long>(yield_seconds * 1e6);
    itimerval timer{};
    timer.it_value.tv_sec = micros / 1000000;
    timer.it_value.tv_usec = micros % 1000000;
    setitimer(ITIMER_PROF, &timer, nullptr);
  }
  // Gone with the server: a parse nobody can read the answer of stops. (No
  // test of getppid() for a parent gone already: in a container the server
  // is process 1; such an orphan's parse still ends at its limits.)
  prctl(PR_SET_PDEATHSIG, SIGKILL);
  Limit(RLIMIT_CPU, cpu_seconds, cpu_seconds + 1);
  Limit(RLIMIT_AS, memory_bytes, memory_bytes);
  rlimit no_core{0, 0};
  setrlimit(RLIMIT_CORE, &no_core);

  auto format = sfc::cad::ParseModelFormat(argv[1]);
  if (!format.ok()) return Print(2, "usage: unknown format");
  try {
    const std::string bytes{std::istreambuf_iterator<char>(std::cin),
                            std::istreambuf_iterator<char>()};
    sfc::cad::LoadOptions options;
    options.max_bytes = std::max(options.max_bytes, bytes.size());
    auto brep = sfc::cad::ReadToBrep(*format, bytes, argv[2], options);
    if (!brep.ok()) {
      return Print(1, std::to_string(static_cast<int>(brep.status().code())) + " " +
                          std::string(brep.status().message()));
    }
    std::printf("ok %zu\n", brep->size());
    std::fwrite(brep->data(), 1, brep->size(), stdout);
    std::fflush(stdout);
    return 0;
  } catch (const std::bad_alloc&) {
    return Print(1, std::to_string(static_cast<int>(absl::StatusCode::kResourceExhausted)) +
                        " out of memory while reading the model");
  } catch (const std::exception& e) {
    return Print(1, std::to_string(static_cast<int>(absl::StatusCode::kInvalidArgument)) +
                        " reading the model failed: " + e.what());
  }
}
