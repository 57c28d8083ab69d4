// A batch of samples handed to NumPy as a dict of arrays, the embedded
// sampler's (sampling.cc) and the client's (client.cc) alike: index
// (uint64), the value columns u ... curve_position (float64, or float32 when
// narrowed), face and triangle (uint32). Each vector becomes its array's
// buffer without a copy (arrays.h); with a pool, the buffers come from it and
// go back to it when the arrays are freed (buffer_pool.h).
#ifndef SFCSAMPLER_PYTHON_BINDINGS_BATCH_COLUMNS_H_
#define SFCSAMPLER_PYTHON_BINDINGS_BATCH_COLUMNS_H_

#include <array>
#include <memory>
#include <vector>

#include "core/types/sample_batch.h"
#include "pybind11/pybind11.h"
#include "python/bindings/buffer_pool.h"

namespace sfc::python {

struct BatchColumns {
  SampleBatch batch;
  // The value columns as float32, in SampleBatch::ValueColumns() order, once
  // Narrow() has run.
  std::array<std::vector<float>, 10> narrowed;
  bool float32 = false;
};

// Gives `batch` (empty) room for `n` samples in every column a cursor with
// `fields` fills, from `pool`. Needs no GIL.
void TakeColumns(const SampleFields& fields, size_t n, BufferPool& pool, SampleBatch* batch);

// Rounds each value column to the nearest float into `narrowed` and frees
// the doubles (into `pool`, and the floats from it, when there is one).
// Needs no GIL.
void Narrow(BatchColumns* columns, BufferPool* pool = nullptr);

// The dict of arrays: index, face and triangle when `fields` ask for them,
// and every value column that holds samples; their buffers go back to `pool`
// when the arrays are freed. REQUIRES the GIL.
pybind11::dict ColumnsDict(BatchColumns&& columns, const SampleFields& fields,
                           const std::shared_ptr<BufferPool>& pool = nullptr);

}  // namespace sfc::python

#endif  // SFCSAMPLER_PYTHON_BINDINGS_BATCH_COLUMNS_H_
