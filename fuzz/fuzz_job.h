// Shared by the request fuzzers: an engine with tiny limits (so no input can
// make a target build a large tree or sort a large range), and a checker that
// runs an accepted request to the end and traps when a sample breaks the
// request's contract. Not thread-safe (one libFuzzer thread per process).
#ifndef SFCSAMPLER_FUZZ_FUZZ_JOB_H_
#define SFCSAMPLER_FUZZ_FUZZ_JOB_H_

#include "engine/sampling_engine.h"
#include "request/sample_request.h"

namespace sfc::fuzz {

// max_count 4096, max_tree_leaves 4096, max_spec_length 512,
// max_sorted_range 4096: every accepted request finishes in milliseconds.
EngineLimits SmallLimits();

// Validates `request` with an engine of SmallLimits() and, when it is
// accepted, drains its cursor. Traps (a crash libFuzzer reports) when an
// error has no message or a non-canonical code for bad input, when a sample
// has an index outside the resolved range, a repeated index, a non-finite
// coordinate or parameters outside the unit square, or when a request without
// a region yields other than end - begin samples.
void CheckRequest(const SampleRequest& request);

}  // namespace sfc::fuzz

#endif  // SFCSAMPLER_FUZZ_FUZZ_JOB_H_
