#include "python/bindings/errors.h"

#include "python/bindings/register.h"

namespace py = pybind11;

namespace sfc::python {

void RegisterErrors(py::module_& m) {
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const StatusException& e) {
      // The exception classes live in pure Python (sfcsampler/errors.py), one
      // set for both extensions (_core in process, _client over the wire).
      py::object errors = py::module_::import("sfcsampler.errors");
      py::object error = errors.attr("from_status")(static_cast<int>(e.status().code()),
                                                    std::string(e.status().message()));
      PyErr_SetObject(error.get_type().ptr(), error.ptr());
    }
  });
}

}  // namespace sfc::python
