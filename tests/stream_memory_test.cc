// The streams' memory budget: reservations never exceed it together; a
// stream waits for memory and gets it when another ends; a waiting stream
// leaves when its own check fails; an oversized request is refused at once.
#include "server/stream_memory.h"

#include <atomic>
#include <thread>
#include <vector>

#include "gtest/gtest.h"

namespace sfc {
namespace {

TEST(StreamMemory, ReservationsTogetherNeverExceedTheBudget) {
  StreamMemory memory(1000);
  std::atomic<uint64_t> held{0}, peak{0};
  std::vector<std::thread> threads;
  for (int t = 0; t < 8; ++t) {
    threads.emplace_back([&, t] {
      for (int i = 0; i < 50; ++i) {
        auto r = memory.Reserve(100 + 50 * t, "test", "ask for less", nullptr);
        ASSERT_TRUE(r.ok()) << r.status();
        const uint64_t now = held += r->bytes();
        uint64_t p = peak.load();
        while (now > p && !peak.compare_exchange_weak(p, now)) {}
        held -= r->bytes();
      }
    });
  }
  for (auto& t : threads) t.join();
  EXPECT_LE(peak.load(), 1000u);
  EXPECT_EQ(memory.reserved_bytes(), 0u);
}

TEST(StreamMemory, AWaitingStreamGetsTheMemoryAnotherReturns) {
  StreamMemory memory(1000);
  auto first = memory.Reserve(800, "first", "ask for less", nullptr);
  ASSERT_TRUE(first.ok());
  std::atomic<bool> got{false};
  std::thread second([&] {
    auto r = memory.Reserve(500, "second", "ask for less", nullptr);
    EXPECT_TRUE(r.ok());
    got = true;
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  EXPECT_FALSE(got.load());
  *first = StreamMemory::Reservation();  // the first stream ends
  second.join();
  EXPECT_TRUE(got.load());
  EXPECT_EQ(memory.waits(), 1u);
}

TEST(StreamMemory, AWaiterLeavesWhenItsCheckFailsAndTooMuchIsRefusedAtOnce) {
  StreamMemory memory(1000);
  auto held = memory.Reserve(1000, "held", "ask for less", nullptr);
  ASSERT_TRUE(held.ok());
  std::atomic<int> asked{0};
  auto r = memory.Reserve(10, "waiter", "ask for less", [&]() -> absl::Status {
    return ++asked > 3 ? absl::CancelledError("client gone") : absl::OkStatus();
  });
  EXPECT_EQ(r.status().code(), absl::StatusCode::kCancelled);
  EXPECT_EQ(memory.reserved_bytes(), 1000u);

  auto big = memory.Reserve(1001, "a sorted range", "ask for less", nullptr);
  EXPECT_EQ(big.status().code(), absl::StatusCode::kResourceExhausted);
  EXPECT_NE(big.status().message().find("stream_memory_bytes"), std::string::npos);
  EXPECT_NE(big.status().message().find("; ask for less"), std::string::npos);
}

}  // namespace
}  // namespace sfc
