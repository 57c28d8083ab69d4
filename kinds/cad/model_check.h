// Reading a CAD file where a crash or a loop costs one request, not the
// server: OpenCASCADE's readers have loops that never poll the user break
// (fuzzing found an IGES file that spins forever in Geom2d_TrimmedCurve::
// SetTrim under ShapeFix_Wire::FixLacking), and a thread cannot be stopped
// from outside; on broken STEP files the reader leaks; the IGES reader keeps
// state from one file to the next, and a fault the kernel turns into an
// exception can leave the heap or a lock broken for later files (found by
// iges_fuzzer, docs/MODELS.md). So the server (and sample-many, which also
// reads many files in one process) never runs the readers itself: it reads
// each file in sfcsampler-model-check (kinds/cad/model_check_main.cc), a
// process of its own with CPU, memory and wall-clock limits, which sends back
// the model's shape as binary BRep (cad::ReadToBrep); the caller makes the
// model of that (cad::LoadBrep), the same model Load makes of the file.
// docs/MODELS.md gives the measured cost.
//
// Thread-safety: thread-safe.
#ifndef SFCSAMPLER_KINDS_CAD_MODEL_CHECK_H_
#define SFCSAMPLER_KINDS_CAD_MODEL_CHECK_H_

#include <cstdint>
#include <functional>
#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "request/model_spec.h"

namespace sfc {

struct ModelCheckLimits {
  std::string program;        // path of sfcsampler-model-check
  double cpu_seconds = 0;     // of the check process; 0 = none
  uint64_t memory_bytes = 0;  // its address space; 0 = none
  // CPU seconds after which it runs in the idle scheduling class; 0 = never.
  double yield_seconds = 0;
};

// The model's shape as binary BRep, read in the check process. Else the
// loader's own error, or: INVALID_ARGUMENT when the kernel crashed on the
// file; RESOURCE_EXHAUSTED when the check ran out of CPU time, memory or
// wall-clock time (4x its CPU limit, at least 10 s); INTERNAL when the
// program cannot be run or its answer is malformed; `check`'s status when it
// said to stop (the process is killed).
absl::StatusOr<std::string> ReadModelInSubprocess(const ModelCheckLimits& limits,
                                                  ModelFormat format, const std::string& bytes,
                                                  const std::string& name,
                                                  const std::function<absl::Status()>& check);

}  // namespace sfc

#endif  // SFCSAMPLER_KINDS_CAD_MODEL_CHECK_H_
