// LoadedModels (engine/loaded_models.h): parses on threads of their own,
// one parse per key, failures remembered, a byte budget, stops when nobody
// waits or the CPU budget is spent, and a caller that leaves at once.
#include "engine/loaded_models.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <string>
#include <thread>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/synchronization/mutex.h"
#include "gtest/gtest.h"

namespace sfc {
namespace {

using Parsed = LoadedModels::Parsed;

LoadedModels::ParseFn Returning(uint64_t bytes, std::atomic<int>* parses) {
  return [bytes, parses](const ParseCheck&) -> absl::StatusOr<Parsed> {
    ++*parses;
    return Parsed{std::make_shared<const int>(7), bytes};
  };
}

// Spins (checking) until told to stop; returns the check's status.
LoadedModels::ParseFn Spinning(std::atomic<bool>* started) {
  return [started](const ParseCheck& check) -> absl::StatusOr<Parsed> {
    *started = true;
    while (true) {
      if (absl::Status s = check(); !s.ok()) return s;
    }
  };
}

TEST(LoadedModels, KeepsWithinItsByteBudgetLeastRecentlyUsedFirstOut) {
  LoadedModelsOptions o;
  o.budget_bytes = 250;
  LoadedModels loaded(o);
  std::atomic<int> parses{0};
  for (const char* key : {"a", "b", "c"}) {
    ASSERT_TRUE(loaded.Get<int>(key, Returning(100, &parses), nullptr, 0).ok());
  }
  EXPECT_EQ(loaded.stats().bytes, 200u);
  EXPECT_EQ(loaded.stats().models, 2u);
  EXPECT_EQ(loaded.stats().evictions, 1u);
  ASSERT_TRUE(loaded.Get<int>("c", Returning(100, &parses), nullptr, 0).ok());
  EXPECT_EQ(parses.load(), 3);  // c was kept
  ASSERT_TRUE(loaded.Get<int>("a", Returning(100, &parses), nullptr, 0).ok());
  EXPECT_EQ(parses.load(), 4);  // a was evicted
  // Larger than the whole budget: returned, not kept.
  auto big = loaded.Get<int>("big", Returning(1000, &parses), nullptr, 0);
  ASSERT_TRUE(big.ok());
  EXPECT_EQ(**big, 7);
  EXPECT_LE(loaded.stats().bytes, 250u);
}

TEST(LoadedModels, ConcurrentRequestsShareOneParseAndFailuresAreRemembered) {
  LoadedModels loaded;
  std::atomic<int> parses{0};
  auto slow = [&parses](const ParseCheck&) -> absl::StatusOr<Parsed> {
    ++parses;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    return Parsed{std::make_shared<const int>(1), 8};
  };
  std::vector<std::thread> threads;
  for (int i = 0; i < 8; ++i) {
    threads.emplace_back([&] { EXPECT_TRUE(loaded.Get<int>("k", slow, nullptr, 0).ok()); });
  }
  for (auto& t : threads) t.join();
  EXPECT_EQ(parses.load(), 1);

  std::atomic<int> failures{0};
  auto failing = [&failures](const ParseCheck&) -> absl::StatusOr<Parsed> {
    ++failures;
    return absl::InvalidArgumentError("bad face");
  };
  EXPECT_EQ(loaded.Get<int>("sha256=ab|x", failing, nullptr, 0).status().message(), "bad face");
  EXPECT_EQ(loaded.Get<int>("sha256=ab|x", failing, nullptr, 0).status().message(), "bad face");
  EXPECT_EQ(failures.load(), 1);
  EXPECT_EQ(loaded.stats().failure_hits, 1u);
  loaded.ForgetModel("ab");  // forgets failures too
  EXPECT_FALSE(loaded.Get<int>("sha256=ab|x", failing, nullptr, 0).ok());
  EXPECT_EQ(failures.load(), 2);
}

TEST(LoadedModels, TheCpuBudgetStopsAParse) {
  LoadedModelsOptions o;
  o.parse_seconds = 0.2;
  LoadedModels loaded(o);
  std::atomic<bool> started{false};
  auto s = loaded.Get<int>("spin", Spinning(&started), nullptr, 0);
  EXPECT_EQ(s.status().code(), absl::StatusCode::kResourceExhausted) << s.status();
  EXPECT_NE(s.status().message().find("model_parse_seconds"), std::string::npos);
  EXPECT_EQ(loaded.stats().parses_stopped, 1u);
}

// parse_threads = 0: each parse runs on the thread that asked for it; the
// one-parse-per-key rule, remembered failures and the CPU budget still hold.
TEST(LoadedModels, WithoutParseThreadsTheCallerParsesUnderTheSameRules) {
  LoadedModelsOptions o;
  o.parse_threads = 0;
  o.parse_seconds = 0.2;
  LoadedModels loaded(o);
  std::atomic<int> parses{0};
  absl::Mutex mu;
  std::vector<std::thread::id> parsed_on;
  auto slow = [&](const ParseCheck&) -> absl::StatusOr<Parsed> {
    ++parses;
    {
      absl::MutexLock lock(&mu);
      parsed_on.push_back(std::this_thread::get_id());
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    return Parsed{std::make_shared<const int>(1), 8};
  };
  std::vector<std::thread> threads;
  std::vector<std::thread::id> callers(6);
  for (int i = 0; i < 6; ++i) {
    threads.emplace_back([&, i] {
      callers[i] = std::this_thread::get_id();
      EXPECT_TRUE(loaded.Get<int>(i < 3 ? "k" : "other", slow, nullptr, 0).ok());
    });
  }
  for (auto& t : threads) t.join();
  EXPECT_EQ(parses.load(), 2);  // one per key
  for (const auto& id : parsed_on) {
    EXPECT_NE(std::find(callers.begin(), callers.end(), id), callers.end());  // a caller's thread
  }
  std::atomic<bool> started{false};
  auto spin = loaded.Get<int>("spin", Spinning(&started), nullptr, 0);
  EXPECT_EQ(spin.status().code(), absl::StatusCode::kResourceExhausted) << spin.status();
  EXPECT_EQ(loaded.Get<int>("spin", Spinning(&started), nullptr, 0).status().code(),
            absl::StatusCode::kResourceExhausted);  // remembered
  EXPECT_EQ(loaded.stats().failure_hits, 1u);
  EXPECT_EQ(loaded.stats().parsing, 0u);

  // The parsing caller's own check stops its parse, which is not remembered
  // as the model's failure; a parser's unknown exception ends the job too.
  LoadedModelsOptions unbounded;
  unbounded.parse_threads = 0;
  LoadedModels inline_only(unbounded);
  const auto start = std::chrono::steady_clock::now();
  auto deadline = [start]() {
    return std::chrono::steady_clock::now() - start > std::chrono::milliseconds(100)
               ? absl::DeadlineExceededError("deadline")
               : absl::OkStatus();
  };
  auto left = inline_only.Get<int>("loops", Spinning(&started), deadline, 0);
  EXPECT_EQ(left.status().code(), absl::StatusCode::kDeadlineExceeded) << left.status();
  EXPECT_TRUE(inline_only.Get<int>("loops", Returning(8, &parses), nullptr, 0).ok());
  auto throwing = [](const ParseCheck&) -> absl::StatusOr<Parsed> { throw 42; };
  EXPECT_EQ(inline_only.Get<int>("throws", throwing, nullptr, 0).status().code(),
            absl::StatusCode::kInternal);
  EXPECT_EQ(inline_only.stats().parsing, 0u);
}

TEST(LoadedModels, ACallerLeavesAtOnceAndAParseNobodyWantsStops) {
  LoadedModels loaded;  // no CPU budget: only the callers stop it
  std::atomic<bool> started{false};
  std::atomic<bool> leave{false};
  const auto start = std::chrono::steady_clock::now();
  std::thread t([&] {
    auto s = loaded.Get<int>("spin", Spinning(&started), [&]() -> absl::Status {
      return leave ? absl::CancelledError("client gone") : absl::OkStatus();
    }, 0);
    EXPECT_EQ(s.status().message(), "client gone");
  });
  while (!started) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  leave = true;
  t.join();
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 2.0);
  for (int i = 0; i < 200 && loaded.stats().parsing > 0; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  EXPECT_EQ(loaded.stats().parsing, 0u) << "the abandoned parse did not stop";
  EXPECT_EQ(loaded.stats().parses_stopped, 1u);
  EXPECT_EQ(loaded.stats().parse_failures, 0u);  // not the model's fault: not remembered
}

TEST(LoadedModels, AFullQueueIsResourceExhausted) {
  LoadedModelsOptions o;
  o.max_queued_parses = 1;
  LoadedModels loaded(o);
  std::atomic<bool> started{false}, other{false};
  std::atomic<bool> leave{false};
  auto until_leave = [&]() -> absl::Status {
    return leave ? absl::CancelledError("done") : absl::OkStatus();
  };
  std::thread running(
      [&] { loaded.Get<int>("a", Spinning(&started), until_leave, 0).IgnoreError(); });
  while (!started) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  std::thread queued([&] { loaded.Get<int>("b", Spinning(&other), until_leave, 0).IgnoreError(); });
  while (loaded.stats().queued < 1) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  auto refused = loaded.Get<int>("c", Spinning(&other), nullptr, 0);
  EXPECT_EQ(refused.status().code(), absl::StatusCode::kResourceExhausted);
  EXPECT_NE(refused.status().message().find("max_queued_parses"), std::string::npos);
  leave = true;
  running.join();
  queued.join();
}

// Parses' working memory: a parse whose estimate is past the budget is
// refused before it queues; two whose estimates do not fit together run one
// after the other even with two parse threads.
TEST(LoadedModels, ParsesRunOnlyWhileTheirWorkingMemoryFits) {
  LoadedModelsOptions o;
  o.parse_threads = 2;
  o.working_budget_bytes = 1000;
  LoadedModels loaded(o);
  std::atomic<int> parses{0};
  auto refused = loaded.Get<int>("huge", Returning(1, &parses), nullptr, 1001);
  EXPECT_EQ(refused.status().code(), absl::StatusCode::kResourceExhausted);
  EXPECT_NE(refused.status().message().find("parse_memory_bytes"), std::string::npos);
  EXPECT_EQ(parses, 0);

  std::atomic<bool> first_started{false}, second_started{false}, leave{false};
  auto until_leave = [&]() -> absl::Status {
    return leave ? absl::CancelledError("done") : absl::OkStatus();
  };
  std::thread first(
      [&] { loaded.Get<int>("a", Spinning(&first_started), until_leave, 600).IgnoreError(); });
  while (!first_started) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  EXPECT_EQ(loaded.stats().working_bytes, 600u);
  std::thread second(
      [&] { loaded.Get<int>("b", Spinning(&second_started), until_leave, 600).IgnoreError(); });
  while (loaded.stats().queued < 1) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  EXPECT_FALSE(second_started) << "600 + 600 bytes of parses ran at once on a budget of 1000";
  leave = true;
  first.join();
  second.join();
  // The abandoned parse stops at its next check and gives its memory back.
  for (int i = 0; i < 200 && loaded.stats().working_bytes > 0; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  EXPECT_EQ(loaded.stats().working_bytes, 0u);
  EXPECT_TRUE(loaded.Get<int>("c", Returning(1, &parses), nullptr, 1000).ok());
}

// Of the parses waiting, the smallest starts first (a small model does not
// wait behind large or hostile ones), but none is passed over for good.
TEST(LoadedModels, SmallParsesStartFirstAndNoneIsPassedOverForGood) {
  LoadedModelsOptions o;
  o.parse_threads = 1;
  o.max_queued_parses = 32;
  LoadedModels loaded(o);
  std::atomic<bool> started{false}, leave{false};
  auto until_leave = [&]() -> absl::Status {
    return leave ? absl::CancelledError("done") : absl::OkStatus();
  };
  std::thread running(
      [&] { loaded.Get<int>("busy", Spinning(&started), until_leave, 1).IgnoreError(); });
  while (!started) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  absl::Mutex order_mu;
  std::vector<std::string> order;
  auto recording = [&](const std::string& name) -> LoadedModels::ParseFn {
    return [&, name](const ParseCheck&) -> absl::StatusOr<Parsed> {
      absl::MutexLock lock(&order_mu);
      order.push_back(name);
      return Parsed{std::make_shared<const int>(1), 1};
    };
  };
  // Queued while "busy" runs: a large parse, then ten small ones.
  std::vector<std::thread> waiting;
  waiting.emplace_back(
      [&] { ASSERT_TRUE(loaded.Get<int>("large", recording("large"), nullptr, 1000).ok()); });
  while (loaded.stats().queued < 1) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  for (int i = 0; i < 10; ++i) {
    const std::string name = absl::StrCat("small", i);
    waiting.emplace_back(
        [&, name] { ASSERT_TRUE(loaded.Get<int>(name, recording(name), nullptr, 10).ok()); });
    while (loaded.stats().queued < static_cast<uint64_t>(i + 2)) {
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  }
  leave = true;
  running.join();
  for (std::thread& t : waiting) t.join();
  ASSERT_EQ(order.size(), 11u);
  // Eight small ones pass the large one, which then starts: it waited for
  // at most kMaxPassedOver (8) smaller parses.
  const size_t large = std::find(order.begin(), order.end(), "large") - order.begin();
  EXPECT_EQ(large, 8u);
  EXPECT_EQ(order.front().rfind("small", 0), 0u);
}

// Issue 37: a parse past fresh_seconds leaves its slot, so a small model
// parses while a hostile one runs on; past max_long_parses a long parse is
// stopped as the server's load (not remembered: the next request parses).
TEST(LoadedModels, ALongParseLeavesItsSlotToTheParsesWaiting) {
  LoadedModelsOptions o;
  o.parse_threads = 1;
  o.fresh_seconds = 0.05;
  o.max_long_parses = 1;
  LoadedModels loaded(o);
  std::atomic<bool> started{false}, other{false}, leave{false};
  auto until_leave = [&]() -> absl::Status {
    return leave ? absl::CancelledError("done") : absl::OkStatus();
  };
  absl::Status hog_status;
  std::thread hog(
      [&] { hog_status = loaded.Get<int>("hog", Spinning(&started), until_leave, 1).status(); });
  while (loaded.stats().long_parses < 1) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  std::atomic<int> parses{0};
  EXPECT_TRUE(loaded.Get<int>("small", Returning(1, &parses), nullptr, 1).ok());
  EXPECT_EQ(loaded.stats().parsing, 1u) << "the hog should still run";

  // A second long parse is one past max_long_parses: stopped, with why.
  auto second = loaded.Get<int>("second", Spinning(&other), nullptr, 1);
  EXPECT_EQ(second.status().code(), absl::StatusCode::kResourceExhausted) << second.status();
  EXPECT_NE(second.status().message().find("max_long_parses"), std::string::npos);
  EXPECT_GE(loaded.stats().parses_busy, 1u);
  EXPECT_TRUE(loaded.Get<int>("second", Returning(1, &parses), nullptr, 1).ok()) << "remembered";
  EXPECT_EQ(parses.load(), 2);

  // A smaller parse turning long takes a larger one's place: the larger one
  // (a hostile file, say) is stopped, not the small one a busy machine slowed.
  std::atomic<bool> small_started{false};
  absl::Status small_status;
  std::thread small([&] {
    small_status =
        loaded.Get<int>("small-but-slow", Spinning(&small_started), until_leave, 0).status();
  });
  hog.join();
  EXPECT_EQ(hog_status.code(), absl::StatusCode::kResourceExhausted) << hog_status;
  EXPECT_NE(hog_status.message().find("smaller models needed its place"), std::string::npos)
      << hog_status;
  EXPECT_EQ(loaded.stats().long_parses, 1u) << "the small parse runs on as the long one";
  leave = true;
  small.join();
  EXPECT_EQ(small_status.code(), absl::StatusCode::kCancelled) << small_status;
}

// Issue 37: a full queue takes a smaller parse in place of its largest (a
// flood of large hostile files does not turn small models away), and a
// request leaves a queue it waited in for max_queue_wait_seconds.
TEST(LoadedModels, AFullQueueTakesASmallerParseInPlaceOfItsLargest) {
  LoadedModelsOptions o;
  o.parse_threads = 1;
  o.max_queued_parses = 1;
  LoadedModels loaded(o);
  std::atomic<bool> started{false}, leave{false};
  auto until_leave = [&]() -> absl::Status {
    return leave ? absl::CancelledError("done") : absl::OkStatus();
  };
  std::thread busy(
      [&] { loaded.Get<int>("busy", Spinning(&started), until_leave, 1).IgnoreError(); });
  while (!started) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  std::atomic<int> parses{0};
  absl::Status large_status;
  std::thread large([&] {
    large_status = loaded.Get<int>("large", Returning(1, &parses), nullptr, 1000).status();
  });
  while (loaded.stats().queued < 1) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  std::thread small(
      [&] { EXPECT_TRUE(loaded.Get<int>("small", Returning(1, &parses), nullptr, 10).ok()); });
  large.join();
  EXPECT_EQ(large_status.code(), absl::StatusCode::kResourceExhausted) << large_status;
  EXPECT_NE(large_status.message().find("took this one's place"), std::string::npos)
      << large_status;
  // A parse no smaller than the queued one is turned away as before.
  auto refused = loaded.Get<int>("larger", Returning(1, &parses), nullptr, 10);
  EXPECT_EQ(refused.status().code(), absl::StatusCode::kResourceExhausted);
  EXPECT_NE(refused.status().message().find("max_queued_parses"), std::string::npos);
  leave = true;
  busy.join();
  small.join();
  EXPECT_EQ(parses.load(), 1);
}

TEST(LoadedModels, ARequestLeavesAQueueItWaitedInTooLong) {
  LoadedModelsOptions o;
  o.parse_threads = 1;
  o.max_queue_wait_seconds = 0.05;
  LoadedModels loaded(o);
  std::atomic<bool> started{false}, leave{false};
  auto until_leave = [&]() -> absl::Status {
    return leave ? absl::CancelledError("done") : absl::OkStatus();
  };
  std::thread busy(
      [&] { loaded.Get<int>("busy", Spinning(&started), until_leave, 1).IgnoreError(); });
  while (!started) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  std::atomic<int> parses{0};
  auto waited = loaded.Get<int>("waits", Returning(1, &parses), nullptr, 1);
  EXPECT_EQ(waited.status().code(), absl::StatusCode::kResourceExhausted) << waited.status();
  EXPECT_NE(waited.status().message().find("max_queue_wait_seconds"), std::string::npos);
  leave = true;
  busy.join();
  EXPECT_EQ(parses.load(), 0) << "a parse nobody waits for any more ran";
  EXPECT_TRUE(loaded.Get<int>("waits", Returning(1, &parses), nullptr, 1).ok());
}

}  // namespace
}  // namespace sfc
