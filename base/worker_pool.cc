#include "base/worker_pool.h"

#include <algorithm>
#include <atomic>

namespace sfc {

struct WorkerPool::Loop {
  const std::function<void(int)>* task;
  int n;
  std::atomic<int> next{0};  // the next unclaimed task
  std::mutex mu;
  std::condition_variable finished;
  int done = 0;  // guarded by mu
};

namespace {
std::atomic<WorkerPool*> g_shared_from{nullptr};  // set by ShareFrom
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
    loop.done += ran;
    if (loop.done == loop.n) loop.finished.notify_all();
  }
}

void WorkerPool::Work() {
  while (true) {
    std::shared_ptr<Loop> loop;
    {
      std::unique_lock<std::mutex> lock(mu_);
      wake_.wait(lock, [this] { return stopping_ || !queue_.empty(); });
      if (queue_.empty()) return;  // stopping
      loop = std::move(queue_.front());
      queue_.pop_front();
    }
    RunTasks(*loop);  // a loop already finished has nothing left to claim
  }
}

void WorkerPool::ParallelFor(int n, const std::function<void(int)>& task) {
  if (n <= 0) return;
  auto loop = std::make_shared<Loop>();
  loop->task = &task;
  loop->n = n;
  if (n > 1) {
    {
      std::lock_guard<std::mutex> lock(mu_);
      for (int i = 1; i < n; ++i) queue_.push_back(loop);
    }
    for (int i = 1; i < n; ++i) wake_.notify_one();
  }
  RunTasks(*loop);
  std::unique_lock<std::mutex> lock(loop->mu);
  loop->finished.wait(lock, [&] { return loop->done == loop->n; });
}

}  // namespace sfc
