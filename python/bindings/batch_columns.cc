#include "python/bindings/batch_columns.h"

#include <algorithm>
#include <type_traits>

#include "python/bindings/arrays.h"

namespace py = pybind11;

namespace sfc::python {
namespace {

constexpr const char* kValueNames[] = {"u",  "v",  "x",  "y",       "z",
                                       "nx", "ny", "nz", "density", "curve_position"};

}  // namespace

void TakeColumns(const SampleFields& fields, size_t n, BufferPool& pool, SampleBatch* batch) {
  batch->ForEachColumn(fields, [&](auto* column) {
    *column = pool.Take<typename std::remove_pointer_t<decltype(column)>::value_type>(n);
  });
}

void Narrow(BatchColumns* c, BufferPool* pool) {
  const auto& columns = SampleBatch::ValueColumns();
  for (size_t i = 0; i < columns.size(); ++i) {
    std::vector<double>& column = c->batch.*columns[i];
    if (pool != nullptr) c->narrowed[i] = pool->Take<float>(column.size());
    c->narrowed[i].resize(column.size());
    std::transform(column.begin(), column.end(), c->narrowed[i].begin(),
                   [](double d) { return static_cast<float>(d); });
    if (pool != nullptr) {
      pool->Give(std::move(column));
      column = {};
    } else {
      std::vector<double>().swap(column);
    }
  }
  c->float32 = true;
}

py::dict ColumnsDict(BatchColumns&& c, const SampleFields& fields,
                     const std::shared_ptr<BufferPool>& pool) {
  py::dict out;
  out["index"] = ToNumpy(std::move(c.batch.index), pool);
  if (fields.face) out["face"] = ToNumpy(std::move(c.batch.face), pool);
  if (fields.triangle) out["triangle"] = ToNumpy(std::move(c.batch.triangle), pool);
  const auto& columns = SampleBatch::ValueColumns();
  for (size_t i = 0; i < columns.size(); ++i) {
    if (c.float32) {
      if (!c.narrowed[i].empty()) out[kValueNames[i]] = ToNumpy(std::move(c.narrowed[i]), pool);
    } else if (!(c.batch.*columns[i]).empty()) {
      out[kValueNames[i]] = ToNumpy(std::move(c.batch.*columns[i]), pool);
    }
  }
  return out;
}

}  // namespace sfc::python
