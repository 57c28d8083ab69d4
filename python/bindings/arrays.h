// Hands C++ vectors to NumPy without copying: the vector moves to the heap
// and a capsule that deletes it becomes the array's base, so the array owns
// the buffer for as long as Python holds it.
// REQUIRES the GIL (it creates Python objects).
#ifndef SFCSAMPLER_PYTHON_BINDINGS_ARRAYS_H_
#define SFCSAMPLER_PYTHON_BINDINGS_ARRAYS_H_

#include <vector>

#include "pybind11/numpy.h"
#include "pybind11/pybind11.h"

namespace sfc::python {

template <typename T>
pybind11::array_t<T> ToNumpy(std::vector<T>&& values) {
  if (values.empty()) return pybind11::array_t<T>(0);
  auto* owned = new std::vector<T>(std::move(values));
  pybind11::capsule base(owned, [](void* p) { delete static_cast<std::vector<T>*>(p); });
  return pybind11::array_t<T>(static_cast<pybind11::ssize_t>(owned->size()), owned->data(), base);
}

}  // namespace sfc::python

#endif  // SFCSAMPLER_PYTHON_BINDINGS_ARRAYS_H_
