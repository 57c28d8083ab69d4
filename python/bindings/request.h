// sfcsampler._core.Request: the keyword arguments of sfcsampler.sample() and
// Client.sample(), parsed into an engine SampleRequest by the CLI's own
// parser (request/request_flags.h), so the same arguments mean the same
// request as the same `sfcsampler sample` flags. Immutable after
// construction; thread-safe to read.
#ifndef SFCSAMPLER_PYTHON_BINDINGS_REQUEST_H_
#define SFCSAMPLER_PYTHON_BINDINGS_REQUEST_H_

#include "request/request_flags.h"
#include "pybind11/pybind11.h"
#include "request/sample_request.h"

namespace sfc::python {

struct PyRequest {
  RequestFlags flags;     // as given
  SampleRequest request;  // as parsed
};

}  // namespace sfc::python

#endif  // SFCSAMPLER_PYTHON_BINDINGS_REQUEST_H_
