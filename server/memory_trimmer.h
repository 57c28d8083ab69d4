// Gives freed heap memory back to the system now and then.
//
// glibc keeps the pages of freed small blocks (below the mmap threshold:
// gRPC's slices, protobuf messages, per-stream state) inside its arenas, so
// resident memory stays at its high-water mark between bursts. Measured in the
// soak (tools/soak.sh) at 340 MiB resident: 42 MB of the arenas' 75 MB was
// free. malloc_trim(0) returns the whole free pages inside the arenas
// (madvise), not only the arenas' tops. A background thread calls it every
// interval (the soak's peak RSS fell from 348-494 MiB to 322-325 MiB).
//
// Thread-safety: thread-safe; the destructor stops and joins the thread.
#ifndef SFCSAMPLER_SERVER_MEMORY_TRIMMER_H_
#define SFCSAMPLER_SERVER_MEMORY_TRIMMER_H_

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <thread>

namespace sfc {

// The server process's malloc settings, set once at start (the server's main,
// and bench/stream_benchmark so that it measures the server as run): a fixed
// mmap threshold of 4 MiB, so that buffers larger than that (sorted index
// ranges, tree arrays) go back to the system when freed and resident memory
// falls back to what the budgets hold (cache_bytes, stream_memory_bytes;
// glibc's adaptive threshold would keep raising it); a heap top kept up to 64 MiB, so that a
// stream's per-message buffers (gRPC's serialized slices of up to 1 MiB, its
// read buffers, 65536-sample columns) reuse resident pages instead of faulting
// in fresh ones for every message (with the threshold fixed, glibc's trim
// threshold would stay at 128 KiB: 5 196 faults a 10^7-sample float32
// stream, against 54 with these settings; docs/MEASURED.md, "Branch
// stream-speed"); and at most 2 arenas, as each stream's producer
// thread would otherwise get one of its own (up to 8 per core), each keeping
// the pages its frees leave behind. What the heap keeps goes back within one
// MemoryTrimmer interval (malloc_trim returns free pages anywhere in the
// arenas; with no trimmer, up to 64 MiB of heap top stays). No-op without
// glibc.
void SetServerMallocOptions();

class MemoryTrimmer {
 public:
  // interval <= 0: no thread (TrimNow() still works).
  explicit MemoryTrimmer(std::chrono::milliseconds interval);
  ~MemoryTrimmer();
  MemoryTrimmer(const MemoryTrimmer&) = delete;
  MemoryTrimmer& operator=(const MemoryTrimmer&) = delete;

  // One pass now; true if the system got memory back. No-op (false) where
  // the C library has no malloc_trim.
  static bool TrimNow();
  uint64_t passes() const;

 private:
  const std::chrono::milliseconds interval_;
  mutable std::mutex mu_;
  std::condition_variable wake_;
  bool stopping_ = false;
  uint64_t passes_ = 0;
  std::thread thread_;
};

}  // namespace sfc

#endif  // SFCSAMPLER_SERVER_MEMORY_TRIMMER_H_
