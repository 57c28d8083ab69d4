#include "python/bindings/batch_columns.h"

#include <algorithm>

#include "python/bindings/arrays.h"

namespace py = pybind11;

namespace sfc::python {
namespace {

constexpr const char* kValueNames[] = {"u",  "v",  "x",  "y",       "z",
                                       "nx", "ny", "nz", "density", "curve_position"};

}  // namespace

void Narrow(BatchColumns* c) {
  const auto& columns = SampleBatch::ValueColumns();
  for (size_t i = 0; i < columns.size(); ++i) {
    std::vector<double>& column = c->batch.*columns[i];
    c->narrowed[i].resize(column.size());
    std::transform(column.begin(), column.end(), c->narrowed[i].begin(),
                   [](double d) { return static_cast<float>(d); });
    std::vector<double>().swap(column);
  }
  c->float32 = true;
}

py::dict ColumnsDict(BatchColumns&& c, const SampleFields& fields) {
  py::dict out;
  out["index"] = ToNumpy(std::move(c.batch.index));
  if (fields.face) out["face"] = ToNumpy(std::move(c.batch.face));
  if (fields.triangle) out["triangle"] = ToNumpy(std::move(c.batch.triangle));
  const auto& columns = SampleBatch::ValueColumns();
  for (size_t i = 0; i < columns.size(); ++i) {
    if (c.float32) {
      if (!c.narrowed[i].empty()) out[kValueNames[i]] = ToNumpy(std::move(c.narrowed[i]));
    } else if (!(c.batch.*columns[i]).empty()) {
      out[kValueNames[i]] = ToNumpy(std::move(c.batch.*columns[i]));
    }
  }
  return out;
}

}  // namespace sfc::python
