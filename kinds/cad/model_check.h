// Reading a CAD file where a crash or a loop costs one request, not the
// server: OpenCASCADE's readers have loops that never poll the user break
// (fuzzing found an IGES file that spins forever in Geom2d_TrimmedCurve::
// SetTrim under ShapeFix_Wire::FixLacking), and a thread cannot be stopped
// from outside. So before the server reads a file in process, it reads it
// once in sfcsampler-model-check (kinds/cad/model_check_main.cc), a process
// of its own with CPU, memory and wall-clock limits; only a file that loads
// there is read in process, where the same deterministic load then finishes.
// docs/MODELS.md gives the measured cost.
//
// Thread-safety: thread-safe.
#ifndef SFCSAMPLER_KINDS_CAD_MODEL_CHECK_H_
#define SFCSAMPLER_KINDS_CAD_MODEL_CHECK_H_

#include <cstdint>
#include <functional>
#include <string>

#include "absl/status/status.h"
#include "request/model_spec.h"

namespace sfc {

struct ModelCheckLimits {
  std::string program;        // path of sfcsampler-model-check
  double cpu_seconds = 0;     // of the check process; 0 = none
  uint64_t memory_bytes = 0;  // its address space; 0 = none
};

// OK when the model loads in the check process. Else the loader's own error,
// or: INVALID_ARGUMENT when the kernel crashed on the file; RESOURCE_EXHAUSTED
// when the check ran out of CPU time, memory or wall-clock time (4x its CPU
// limit, at least 10 s); INTERNAL when the program cannot be run; `check`'s
// status when it said to stop (the process is killed).
absl::Status CheckModelInSubprocess(const ModelCheckLimits& limits, ModelFormat format,
                                    const std::string& bytes, const std::string& name,
                                    const std::function<absl::Status()>& check);

}  // namespace sfc

#endif  // SFCSAMPLER_KINDS_CAD_MODEL_CHECK_H_
