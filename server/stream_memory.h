// The server-wide budget for streams' working memory: the index arrays that
// sequences not monotone in k are sorted with (16 bytes a sample while
// sorting), and the batches and messages each stream holds. Trees are
// counted by the tree cache (cache_bytes); this is everything else a request
// makes the server hold, so that peak memory stays at cache_bytes +
// stream_memory_bytes + a fixed overhead however many streams run.
//
// A stream reserves its bytes before it generates anything and returns them
// when it ends. When the budget is taken it waits for other streams to end,
// asking its own check (client gone, deadline) as it waits; a reservation
// larger than the whole budget is refused at once with RESOURCE_EXHAUSTED.
//
// Thread-safety: thread-safe.
#ifndef SFCSAMPLER_SERVER_STREAM_MEMORY_H_
#define SFCSAMPLER_SERVER_STREAM_MEMORY_H_

#include <cstdint>
#include <functional>

#include "absl/base/thread_annotations.h"
#include "absl/status/statusor.h"
#include "absl/synchronization/mutex.h"

namespace sfc {

class StreamMemory {
 public:
  // Returns its bytes to the budget when destroyed.
  class Reservation {
   public:
    Reservation() = default;
    Reservation(Reservation&& other) noexcept;
    Reservation& operator=(Reservation&& other) noexcept;
    ~Reservation();
    uint64_t bytes() const { return bytes_; }

   private:
    friend class StreamMemory;
    Reservation(StreamMemory* owner, uint64_t bytes) : owner_(owner), bytes_(bytes) {}
    StreamMemory* owner_ = nullptr;
    uint64_t bytes_ = 0;
  };

  explicit StreamMemory(uint64_t budget_bytes) : budget_(budget_bytes) {}

  // Reserves `bytes`, waiting while other streams hold the budget. `check` is
  // asked every few milliseconds while waiting; its non-OK status ends the
  // wait with that status. RESOURCE_EXHAUSTED when `bytes` exceeds the
  // budget; `what` names the request's part that needs them and `advice`
  // says what would need less, for the message.
  // OK, or the RESOURCE_EXHAUSTED Reserve gives at once for `bytes` over the
  // whole budget: for a caller that refuses such a request before it does
  // anything costly for it.
  absl::Status CheckFits(uint64_t bytes, const char* what, const char* advice) const;
  absl::StatusOr<Reservation> Reserve(uint64_t bytes, const char* what, const char* advice,
                                      const std::function<absl::Status()>& check)
      ABSL_LOCKS_EXCLUDED(mu_);

  uint64_t budget_bytes() const { return budget_; }
  uint64_t reserved_bytes() const ABSL_LOCKS_EXCLUDED(mu_);
  uint64_t waits() const ABSL_LOCKS_EXCLUDED(mu_);  // reservations that had to wait

 private:
  void Release(uint64_t bytes) ABSL_LOCKS_EXCLUDED(mu_);

  const uint64_t budget_;
  mutable absl::Mutex mu_;
  uint64_t reserved_ ABSL_GUARDED_BY(mu_) = 0;
  uint64_t waits_ ABSL_GUARDED_BY(mu_) = 0;
};

}  // namespace sfc

#endif  // SFCSAMPLER_SERVER_STREAM_MEMORY_H_
