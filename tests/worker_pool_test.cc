// The shared worker pool: every task runs exactly once, loops from many
// callers at once all finish (callers run what no worker takes), and the
// pool's threads are the only ones it starts.
#include "base/worker_pool.h"

#include <atomic>
#include <chrono>
#include <thread>
#include <vector>

#include "gtest/gtest.h"

namespace sfc {
namespace {

TEST(WorkerPool, EveryTaskRunsExactlyOnce) {
  WorkerPool pool(3);
  for (int n : {1, 2, 7, 64}) {
    std::vector<std::atomic<int>> runs(n);
    pool.ParallelFor(n, [&](int i) { ++runs[i]; });
    for (int i = 0; i < n; ++i) EXPECT_EQ(runs[i].load(), 1) << "task " << i << " of " << n;
  }
}

TEST(WorkerPool, ManyCallersAtOnceAllFinishOnASmallPool) {
  WorkerPool pool(1);
  std::atomic<long> total{0};
  std::vector<std::thread> callers;
  for (int c = 0; c < 8; ++c) {
    callers.emplace_back([&] {
      for (int r = 0; r < 50; ++r) {
        pool.ParallelFor(4, [&](int i) { total += i + 1; });
      }
    });
  }
  for (auto& t : callers) t.join();
  EXPECT_EQ(total.load(), 8L * 50 * (1 + 2 + 3 + 4));
}

// A worker polls for a while after a loop, then sleeps: a loop must reach it
// in both states. Task 0 waits (up to 10 s) for task 1 to start, which only a
// worker can do while the caller is inside task 0.
TEST(WorkerPool, AWorkerTakesLoopsWhetherPollingOrAsleep) {
  WorkerPool pool(1);
  for (int us : {0, 20, 20000, 0}) {
    const std::chrono::microseconds idle(us);
    std::this_thread::sleep_for(idle);
    std::atomic<bool> second_started{false};
    bool seen = false;
    pool.ParallelFor(2, [&](int i) {
      if (i == 1) {
        second_started = true;
        return;
      }
      const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
      while (!second_started && std::chrono::steady_clock::now() < deadline) {
        std::this_thread::yield();
      }
      seen = second_started;
    });
    EXPECT_TRUE(seen) << "after " << idle.count() << " us idle, no worker took task 1";
  }
}

// A caller polls for its loop's end for a while, then sleeps: a worker's task
// that outlasts the poll must still wake it. Tasks on other threads sleep 1 ms.
TEST(WorkerPool, ACallerThatStopsPollingIsWokenWhenItsLoopEnds) {
  WorkerPool pool(1);
  const std::thread::id caller = std::this_thread::get_id();
  for (int round = 0; round < 50; ++round) {
    std::atomic<int> ran{0};
    pool.ParallelFor(2, [&](int) {
      if (std::this_thread::get_id() != caller) {
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
      }
      ++ran;
    });
    ASSERT_EQ(ran.load(), 2) << "round " << round;
  }
}

}  // namespace
}  // namespace sfc
