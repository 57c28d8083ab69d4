// A batch of samples handed to NumPy as a dict of arrays, the embedded
// sampler's (sampling.cc) and the client's (client.cc) alike: index
// (uint64), the value columns u ... curve_position (float64, or float32 when
// narrowed), face and triangle (uint32). Each vector becomes its array's
// buffer without a copy (arrays.h).
#ifndef SFCSAMPLER_PYTHON_BINDINGS_BATCH_COLUMNS_H_
#define SFCSAMPLER_PYTHON_BINDINGS_BATCH_COLUMNS_H_

#include <array>
#include <vector>

#include "core/types/sample_batch.h"
#include "pybind11/pybind11.h"

namespace sfc::python {

struct BatchColumns {
  SampleBatch batch;
  // The value columns as float32, in SampleBatch::ValueColumns() order, once
  // Narrow() has run.
  std::array<std::vector<float>, 10> narrowed;
  bool float32 = false;
};

// Rounds each value column to the nearest float into `narrowed` and frees
// the doubles. Needs no GIL.
void Narrow(BatchColumns* columns);

// The dict of arrays: index, face and triangle when `fields` ask for them,
// and every value column that holds samples. REQUIRES the GIL.
pybind11::dict ColumnsDict(BatchColumns&& columns, const SampleFields& fields);

}  // namespace sfc::python

#endif  // SFCSAMPLER_PYTHON_BINDINGS_BATCH_COLUMNS_H_
