// Hands C++ vectors to NumPy without copying: the vector moves to the heap
// and a capsule that deletes it becomes the array's base, so the array owns
// the buffer for as long as Python holds it. With a pool, the buffer goes
// back to the pool when the array is freed (buffer_pool.h).
// REQUIRES the GIL (it creates Python objects).
#ifndef SFCSAMPLER_PYTHON_BINDINGS_ARRAYS_H_
#define SFCSAMPLER_PYTHON_BINDINGS_ARRAYS_H_

#include <memory>
#include <utility>
#include <vector>

#include "pybind11/numpy.h"
#include "pybind11/pybind11.h"
#include "python/bindings/buffer_pool.h"

namespace sfc::python {

template <typename T>
pybind11::array_t<T> ToNumpy(std::vector<T>&& values, std::shared_ptr<BufferPool> pool = nullptr) {
  if (values.empty()) return pybind11::array_t<T>(0);
  struct Owned {
    std::vector<T> values;
    std::shared_ptr<BufferPool> pool;
    ~Owned() {
      if (pool) pool->Give(std::move(values));
    }
  };
  auto* owned = new Owned{std::move(values), std::move(pool)};
  pybind11::capsule base(owned, [](void* p) { delete static_cast<Owned*>(p); });
  return pybind11::array_t<T>(static_cast<pybind11::ssize_t>(owned->values.size()),
                              owned->values.data(), base);
}

}  // namespace sfc::python

#endif  // SFCSAMPLER_PYTHON_BINDINGS_ARRAYS_H_
