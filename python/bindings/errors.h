// absl::Status -> Python exception. A non-OK status becomes an instance of the
// exception class that sfcsampler.errors maps its canonical code to (e.g.
// sfcsampler.InvalidArgumentError), carrying the code and our message, so the
// embedded path and the gRPC client raise the same exceptions.
// Thread-safety: ThrowIfError may be called without the GIL; the translation
// into a Python exception happens later, under the GIL.
#ifndef SFCSAMPLER_PYTHON_BINDINGS_ERRORS_H_
#define SFCSAMPLER_PYTHON_BINDINGS_ERRORS_H_

#include <stdexcept>
#include <string>

#include "absl/status/status.h"
#include "pybind11/pybind11.h"

namespace sfc::python {

// Carries a non-OK status across the C++/Python boundary.
class StatusException : public std::runtime_error {
 public:
  explicit StatusException(absl::Status status)
      : std::runtime_error(std::string(status.message())), status_(std::move(status)) {}
  const absl::Status& status() const { return status_; }

 private:
  absl::Status status_;
};

// Throws StatusException unless `status` is OK.
inline void ThrowIfError(const absl::Status& status) {
  if (!status.ok()) throw StatusException(status);
}

}  // namespace sfc::python

#endif  // SFCSAMPLER_PYTHON_BINDINGS_ERRORS_H_
