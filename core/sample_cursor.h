// The samples of a CurveSamples (core/curve_samples.h) by index range and
// region, in curve order, a batch at a time: columns are sized once and filled
// in place by the kind's SampleFiller, and a region drops what lies outside it
// afterwards. The result is a pure function of (samples, k): no batch size or
// thread count changes it.
//
// Thread-safety: a SampleCursor is used by one thread at a time.
#ifndef SFCSAMPLER_CORE_SAMPLE_CURSOR_H_
#define SFCSAMPLER_CORE_SAMPLE_CURSOR_H_

#include <cstdint>
#include <memory>
#include <vector>

#include "absl/status/statusor.h"
#include "core/curve_samples.h"
#include "core/types/region.h"
#include "core/types/sample_batch.h"

namespace sfc {

class SampleCursor {
 public:
  // Samples with index in [begin, end) that lie in `region`, in curve order;
  // for a two-dimensional sequence (sobol), the samples at positions
  // [begin, end) of the whole set in curve order (the whole set is placed
  // and sorted: cost O(count log count)).
  // For monotone sequences the cost is proportional to the samples emitted
  // plus the kind's region planning (CurveSamples::PlanRegion); other
  // sequences sort the range by curve position first (cost O(n log n),
  // n = end - begin). Errors: INVALID_ARGUMENT for begin > end, end > count,
  // a region the kind rejects, or an empty region; RESOURCE_EXHAUSTED is not
  // raised here (the caller bounds count). `threads` > 1 lets Next() fill
  // large batches of plain index ranges (and a two-dimensional sequence's
  // warp, sort and batches) with that many threads of the shared pool
  // (base/worker_pool.h); the samples and their order do not change.
  // For a windowed two-dimensional sequence, `in_window` (when not null)
  // lists the indices k that Sequence::InWindow accepts, increasing, as a
  // caller that splits one set into windows finds them all in one pass
  // (cad/model_sampler.h); else the cursor tests every index. Read only
  // during Create.
  static absl::StatusOr<std::unique_ptr<SampleCursor>> Create(
      std::shared_ptr<const CurveSamples> samples, uint64_t begin, uint64_t end,
      const Region& region, const SampleFields& fields, int threads = 1,
      const std::vector<uint32_t>* in_window = nullptr);

  // Appends up to `max` samples to `batch` (which it does not clear) and
  // returns how many; 0 once the cursor is exhausted. Errors: the filler's
  // (INVALID_ARGUMENT when the surface or density is not usable at a
  // sample); the batch is then as it was.
  absl::StatusOr<size_t> Next(size_t max, SampleBatch* batch);

 private:
  SampleCursor(std::shared_ptr<const CurveSamples> samples, Region region, SampleFields fields);
  absl::Status Plan(uint64_t begin, uint64_t end, const std::vector<uint32_t>* in_window);
  absl::StatusOr<size_t> NextRuns(size_t max, SampleBatch* batch);
  // Grows the batch's columns by n rows and returns the new rows.
  SampleRows Grow(SampleBatch* batch, size_t n) const;
  // Shrinks the batch's columns to `rows` rows.
  void Truncate(SampleBatch* batch, size_t rows) const;
  // Fills n rows with samples k0 + i (order null) or order[i], whose mass
  // coordinates must not decrease, through `filler`; or, when `at` is not
  // null, the samples at addresses at[i].
  absl::Status Fill(uint64_t k0, const uint64_t* order, size_t n, SampleFiller& filler,
                    const SampleRows& out, const CurveAddress* at = nullptr) const;
  // Fill's work for n <= kFillRun samples.
  absl::Status FillRun(uint64_t k0, const uint64_t* order, size_t n, SampleFiller& filler,
                       const SampleRows& out, const CurveAddress* at) const;
  // The most samples the filler is handed at once.
  static constexpr size_t kFillRun = size_t{1} << 14;
  // Appends the samples k0 + i (or order[i], or at at[i]), i < n, that lie
  // in the region; returns how many.
  absl::StatusOr<size_t> Generate(uint64_t k0, const uint64_t* order, size_t n,
                                  SampleBatch* batch, const CurveAddress* at = nullptr);
  // Appends [k0, k0 + n) (or the samples at at[i], i < n), all kept (no
  // region), split over threads_ threads.
  absl::Status GenerateParallel(uint64_t k0, size_t n, SampleBatch* batch,
                                const CurveAddress* at = nullptr);

  const std::shared_ptr<const CurveSamples> samples_;
  const Region region_;
  const SampleFields fields_;
  // Monotone sequences: index segments in curve order.
  std::vector<IndexSegment> segments_;
  size_t segment_ = 0;
  uint64_t next_k_ = 0;
  // Other sequences: the indices sorted by curve position.
  std::vector<uint64_t> order_;
  size_t order_pos_ = 0;
  bool use_order_ = false;
  // Two-dimensional sequences: the addresses of the range, in curve order
  // (order_pos_ walks them).
  std::vector<CurveAddress> addresses_;
  bool use_addresses_ = false;
  // The cursor's own filler, and those of parallel parts 1, 2, ..., made at
  // their first batch and kept with their scratch memory: a filler made for
  // each batch faulted in its buffers every time (two threads: 1.70-1.73x
  // before, 1.75-1.77x after, docs/MEASURED.md).
  std::unique_ptr<SampleFiller> filler_;
  std::vector<std::unique_ptr<SampleFiller>> part_fillers_;
  int threads_ = 1;
};

}  // namespace sfc

#endif  // SFCSAMPLER_CORE_SAMPLE_CURSOR_H_
