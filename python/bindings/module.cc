// sfcsampler._core: the C++ sampler inside Python. The public API is the
// pure-Python package sfcsampler (python/sfcsampler/), which wraps this.
#include "pybind11/pybind11.h"
#include "python/bindings/register.h"

PYBIND11_MODULE(_core, m) {
  m.doc() = "sfcsampler's C++ core (use the sfcsampler package, not this module)";
  sfc::python::RegisterErrors(m);
  sfc::python::RegisterRequest(m);
  sfc::python::RegisterSampling(m);
  sfc::python::RegisterCatalog(m);
}
