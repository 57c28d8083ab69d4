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
