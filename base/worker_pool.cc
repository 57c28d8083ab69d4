#include "base/worker_pool.h"

#include <algorithm>
#include <atomic>
#include <chrono>

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#endif

namespace sfc {

struct WorkerPool::Loop {
  const std::function<void(int)>* task;
  int n;
  std::chrono::steady_clock::time_point queued_at;  // when ParallelFor offered it
  std::atomic<int> next{0};                         // the next unclaimed task
  std::mutex mu;
  std::condition_variable finished;
  std::atomic<int> done{0};  // written under mu; read without it while spinning
};

namespace {
std::atomic<WorkerPool*> g_shared_from{nullptr};  // set by ShareFrom

// How long a thread polls at most before it sleeps, when it waits for a loop's
// tasks (a worker) or for a loop to finish (its caller). A cursor's batches
// follow each other within microseconds, while waking a sleeping thread takes
// tens of them; split in two, a 64 Ki-sample batch is 0.5 ms a part, so one
// wake-up a batch on each side cost two threads about a tenth of their speed
// (docs/MEASURED.md, "Threads that stay awake between batches"). A worker
// halves its poll each time the next loop came later than kSpin, and doubles
// it when one came sooner: a server that encodes and sends each batch between
// loops would otherwise burn a full poll a batch.
constexpr auto kSpin = std::chrono::microseconds(100);

void Pause() {
#if defined(__x86_64__) || defined(__i386__)
  _mm_pause();
#elif defined(__aarch64__)
  asm volatile("yield");
#endif
}

// Polls `ready` until it holds or `spin` has passed; returns whether it held.
// Between rounds of polls it offers its core to any other runnable thread
// (the one it waits for may need it, where threads outnumber cores).
template <typename Ready>
bool SpinUntil(std::chrono::nanoseconds spin, Ready ready) {
  if (spin.count() == 0) return ready();
  const auto deadline = std::chrono::steady_clock::now() + spin;
  while (true) {
    for (int i = 0; i < 64; ++i) {
      if (ready()) return true;
      Pause();
    }
    if (std::chrono::steady_clock::now() >= deadline) return ready();
    std::this_thread::yield();
  }
}
}  // namespace

WorkerPool& WorkerPool::Shared() {
  static WorkerPool* const pool = [] {
    if (WorkerPool* shared = g_shared_from.load()) return shared;
    return new WorkerPool(
        std::clamp(static_cast<int>(std::thread::hardware_concurrency()) - 1, 1, 63));
  }();
  return *pool;
}

void WorkerPool::ShareFrom(WorkerPool* pool) { g_shared_from.store(pool); }

WorkerPool::WorkerPool(int workers) {
  for (int i = 0; i < workers; ++i) threads_.emplace_back([this] { Work(); });
}

WorkerPool::~WorkerPool() {
  {
    std::lock_guard<std::mutex> lock(mu_);
    stopping_ = true;
  }
  wake_.notify_all();
  for (std::thread& t : threads_) t.join();
}

void WorkerPool::RunTasks(Loop& loop) {
  int ran = 0;
  for (int i = loop.next.fetch_add(1); i < loop.n; i = loop.next.fetch_add(1)) {
    (*loop.task)(i);
    ++ran;
  }
  if (ran > 0) {
    std::lock_guard<std::mutex> lock(loop.mu);
    if (loop.done.fetch_add(ran) + ran == loop.n) loop.finished.notify_all();
  }
}

void WorkerPool::Work() {
  std::chrono::nanoseconds spin = kSpin;
  while (true) {
    const auto idle_from = std::chrono::steady_clock::now();
    SpinUntil(spin, [this] { return queued_.load(std::memory_order_acquire) > 0; });
    std::shared_ptr<Loop> loop;
    {
      std::unique_lock<std::mutex> lock(mu_);
      wake_.wait(lock, [this] { return stopping_ || !queue_.empty(); });
      if (queue_.empty()) return;  // stopping
      loop = std::move(queue_.front());
      queue_.pop_front();
      queued_.store(static_cast<int>(queue_.size()), std::memory_order_release);
    }
    // A loop offered within kSpin of the last one would have been caught by
    // a full poll (timed from its offer, not from this thread's wake-up).
    const bool soon = loop->queued_at - idle_from <= kSpin;
    spin = soon ? std::min<std::chrono::nanoseconds>(
                      std::max(2 * spin, std::chrono::nanoseconds(1000)), kSpin)
                : spin / 2;
    RunTasks(*loop);  // a loop already finished has nothing left to claim
  }
}

void WorkerPool::ParallelFor(int n, const std::function<void(int)>& task) {
  if (n <= 0) return;
  auto loop = std::make_shared<Loop>();
  loop->task = &task;
  loop->n = n;
  loop->queued_at = std::chrono::steady_clock::now();
  if (n > 1) {
    {
      std::lock_guard<std::mutex> lock(mu_);
      for (int i = 1; i < n; ++i) queue_.push_back(loop);
      queued_.store(static_cast<int>(queue_.size()), std::memory_order_release);
    }
    for (int i = 1; i < n; ++i) wake_.notify_one();
  }
  RunTasks(*loop);
  if (SpinUntil(kSpin, [&] { return loop->done.load(std::memory_order_acquire) == loop->n; })) {
    return;
  }
  std::unique_lock<std::mutex> lock(loop->mu);
  loop->finished.wait(lock, [&] { return loop->done.load() == loop->n; });
}

}  // namespace sfc
