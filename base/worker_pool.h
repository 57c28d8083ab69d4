// One bounded pool of worker threads shared by every cursor in the process
// (issue 9: "one bounded worker pool shared by all streams, not threads
// started per batch"). A parallel loop hands its tasks to whichever workers
// are free and runs the rest on the calling thread, so it always finishes,
// even when every worker is busy with other streams' loops; the total number
// of threads stays the pool's size plus the callers.
//
// Which thread runs a task never matters to the result: tasks write to their
// own outputs, which the caller joins in task order.
//
// Idle threads poll for up to 100 us before they sleep (a worker for the next
// loop, a caller for its loop's end), since waking a sleeping thread takes
// tens of microseconds; that time shows in the process's CPU time.
//
// Thread-safety: thread-safe.
#ifndef SFCSAMPLER_BASE_WORKER_POOL_H_
#define SFCSAMPLER_BASE_WORKER_POOL_H_

#include <atomic>
#include <condition_variable>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

namespace sfc {

class WorkerPool {
 public:
  // The process's pool: hardware threads - 1 workers (at least 1, at most 63).
  static WorkerPool& Shared();
  // For a kind module (kinds/module_kind.h), which has its own copy of this
  // code: makes its Shared() the program's pool, so a process keeps one
  // pool. Call before the module's first Shared(); `pool` outlives it.
  static void ShareFrom(WorkerPool* pool);

  explicit WorkerPool(int workers);
  ~WorkerPool();
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  // Runs task(0) .. task(n - 1), each exactly once, on the caller and on free
  // workers; returns when all have finished.
  void ParallelFor(int n, const std::function<void(int)>& task);

  int workers() const { return static_cast<int>(threads_.size()); }

 private:
  struct Loop;
  void Work();
  // Claims and runs tasks of `loop` until none is left unclaimed.
  static void RunTasks(Loop& loop);

  std::mutex mu_;
  std::condition_variable wake_;
  std::deque<std::shared_ptr<Loop>> queue_;  // one entry per task offered to a worker
  // queue_.size(), written under mu_ and polled without it: on a cache line
  // of its own, so polls do not slow the lock's hand-overs.
  alignas(64) std::atomic<int> queued_{0};
  bool stopping_ = false;
  std::vector<std::thread> threads_;
};

}  // namespace sfc

#endif  // SFCSAMPLER_BASE_WORKER_POOL_H_
