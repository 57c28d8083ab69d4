// What a sampling job hands its caller: batches of samples in curve order,
// whatever kind of surface they come from (core's SampleCursor for catalogue,
// expression and CAD surfaces; the mesh cursor for meshes).
//
// Thread-safety: a cursor is used by one thread at a time.
#ifndef SFCSAMPLER_ENGINE_BATCH_CURSOR_H_
#define SFCSAMPLER_ENGINE_BATCH_CURSOR_H_

#include <cstddef>
#include <memory>
#include <utility>

#include "absl/status/statusor.h"
#include "core/sampler.h"
#include "core/types/sample_batch.h"

namespace sfc {

class BatchCursor {
 public:
  virtual ~BatchCursor() = default;
  // Appends up to `max` samples to `batch` (not cleared), with the columns
  // the job asked for, and returns how many; 0 once the cursor is exhausted.
  // Errors as core's SampleCursor::Next.
  virtual absl::StatusOr<size_t> Next(size_t max, SampleBatch* batch) = 0;
};

// core's SampleCursor as a BatchCursor.
class SurfaceBatchCursor final : public BatchCursor {
 public:
  explicit SurfaceBatchCursor(std::unique_ptr<SampleCursor> cursor) : cursor_(std::move(cursor)) {}
  absl::StatusOr<size_t> Next(size_t max, SampleBatch* batch) override {
    return cursor_->Next(max, batch);
  }

 private:
  std::unique_ptr<SampleCursor> cursor_;
};

}  // namespace sfc

#endif  // SFCSAMPLER_ENGINE_BATCH_CURSOR_H_
