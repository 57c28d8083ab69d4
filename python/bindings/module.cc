// sfcsampler._core: the C++ sampler inside Python. The public API is the
// pure-Python package sfcsampler (python/sfcsampler/), which wraps this.
#include <malloc.h>

#include <cstdlib>

#include "pybind11/pybind11.h"
#include "python/bindings/register.h"

namespace {

// Every result's columns are fresh allocations of tens to hundreds of KB that
// numpy frees when the arrays go. With glibc's defaults the freed top of the
// heap above 128 KB goes back to the kernel at once, so the next result
// faults its pages in again: 130 page faults and 0.3 ms of system time for
// each 10 000-sample mesh of bench/many_meshes.py, a fifth of its time. Kept
// instead: heap allocations up to 32 MiB (glibc's own ceiling for its
// adaptive threshold) and up to 64 MiB of free heap top. A process that sets
// MALLOC_MMAP_THRESHOLD_ or MALLOC_TRIM_THRESHOLD_ keeps its own choice.
void KeepFreedColumnMemory() {
  if (std::getenv("MALLOC_MMAP_THRESHOLD_") != nullptr ||
      std::getenv("MALLOC_TRIM_THRESHOLD_") != nullptr) {
    return;
  }
  mallopt(M_MMAP_THRESHOLD, 32 << 20);
  mallopt(M_TRIM_THRESHOLD, 64 << 20);
}

}  // namespace

PYBIND11_MODULE(_core, m) {
  m.doc() = "sfcsampler's C++ core (use the sfcsampler package, not this module)";
  KeepFreedColumnMemory();
  sfc::python::RegisterErrors(m);
  sfc::python::RegisterRequest(m);
  sfc::python::RegisterSampling(m);
  sfc::python::RegisterCatalog(m);
  sfc::python::RegisterModelIdentity(m);
}
