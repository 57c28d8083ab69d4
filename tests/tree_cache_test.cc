// The tree cache's build jobs on their own: exceptions, waiters' checks and
// Stop(), with real trees of the catalogue's surfaces.
#include "server/tree_cache.h"

#include <atomic>
#include <new>
#include <stdexcept>
#include <thread>

#include "catalog/catalog.h"
#include "engine/tree_key.h"
#include "gtest/gtest.h"

namespace sfc {
namespace {

TreeKey Key(const std::string& name) { return MakeTreeKey(name, "uniform", {}); }

TreeFactory Throwing(std::function<void()> thrower) {
  TreeFactory f;
  f.build = [thrower](int, const BuildControl&) -> TreeFactory::Result {
    thrower();
    return absl::InternalError("unreachable");
  };
  f.refine = [thrower](const AnyTree&, int, const BuildControl&) -> TreeFactory::Result {
    thrower();
    return absl::InternalError("unreachable");
  };
  return f;
}

// A real build of `surface` that counts its calls.
TreeFactory Real(const std::string& surface, std::atomic<int>* calls) {
  auto s = *MakeSurface(surface);
  auto d = *MakeDensity("uniform");
  TreeFactory f;
  f.build = [s, d, calls](int grade, const BuildControl& control) {
    ++*calls;
    return AsAnyTree(CurveTree::Build(*s.surface, *d.density, {}, grade, control));
  };
  f.refine = [s, d, calls](const AnyTree& coarser, int grade, const BuildControl& control) {
    ++*calls;
    return AsAnyTree(TreeAs<CurveTree>(&coarser)->Refined(*s.surface, *d.density, grade, control));
  };
  return f;
}

TEST(TreeCache, AnExceptionInABuildBecomesItsStatusAndLeavesNothingPending) {
  TreeCacheOptions options;
  options.failure_ttl_seconds = 0;  // do not remember: the next Get must build again
  TreeCache cache(options);
  auto first = cache.Get(Key("a"), 3, Throwing([] { throw std::runtime_error("boom"); }), {});
  EXPECT_EQ(first.status().code(), absl::StatusCode::kInternal);
  EXPECT_NE(first.status().message().find("boom"), std::string::npos);
  auto oom = cache.Get(Key("b"), 3, Throwing([] { throw std::bad_alloc(); }), {});
  EXPECT_EQ(oom.status().code(), absl::StatusCode::kResourceExhausted);
  // Not stuck pending: the same key builds again, and succeeds.
  std::atomic<int> calls{0};
  auto again = cache.Get(Key("a"), 3, Real("sphere", &calls), {});
  EXPECT_TRUE(again.ok()) << again.status();
  EXPECT_EQ(calls.load(), 1);
  EXPECT_EQ(cache.stats().builds_failed, 2u);
}

TEST(TreeCache, AWaiterWhoseCheckFailsLeavesAtOnce) {
  TreeCache cache(TreeCacheOptions{});
  // A pole the tree refines towards for a minute, unless stopped.
  auto slow = *MakeSurface("expr:x=u;y=v;z=1/(u-0.3)");
  auto d = *MakeDensity("uniform");
  TreeFactory heavy;
  CurveTreeOptions big;
  big.max_leaves = uint64_t{1} << 25;
  heavy.build = [slow, d, big](int grade, const BuildControl& control) {
    return AsAnyTree(CurveTree::Build(*slow.surface, *d.density, big, grade, control));
  };
  heavy.refine = nullptr;
  std::atomic<bool> give_up{false};
  BuildControl caller;
  caller.check = [&]() -> absl::Status {
    return give_up ? absl::DeadlineExceededError("mine") : absl::OkStatus();
  };
  std::thread quit([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    give_up = true;
  });
  const auto start = std::chrono::steady_clock::now();
  auto result = cache.Get(Key("heavy"), CurveTree::GradeFor(100'000'000), heavy, caller);
  quit.join();
  EXPECT_EQ(result.status().code(), absl::StatusCode::kDeadlineExceeded);
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(2));
  cache.Stop();  // the abandoned build stops; Stop joins its thread
  EXPECT_EQ(cache.stats().builds_running, 0u);
  EXPECT_EQ(cache.stats().builds_stopped, 1u);
}

TEST(TreeCache, GrowingTreesCountAgainstTheBudgetAndEvictCachedOnes) {
  TreeCacheOptions options;
  options.budget_bytes = 8 << 20;
  TreeCache cache(options);
  std::atomic<int> calls{0};
  ASSERT_TRUE(cache.Get(Key("s"), 20, Real("sphere", &calls), {}).ok());
  ASSERT_EQ(cache.stats().entries, 1u);
  // A pole the tree refines towards: it grows past 8 MiB long before its
  // own leaf budget, so the cache evicts the sphere for room, then refuses.
  auto pole = *MakeSurface("expr:x=u;y=v;z=1/(u-0.3)");
  auto d = *MakeDensity("uniform");
  TreeFactory heavy;
  heavy.build = [pole, d](int grade, const BuildControl& control) {
    return AsAnyTree(CurveTree::Build(*pole.surface, *d.density, {}, grade, control));
  };
  auto result = cache.Get(Key("pole"), CurveTree::GradeFor(100'000'000), heavy, {});
  EXPECT_EQ(result.status().code(), absl::StatusCode::kResourceExhausted);
  EXPECT_NE(result.status().message().find("cache_bytes"), std::string::npos) << result.status();
  const TreeCacheStats s = cache.stats();
  EXPECT_EQ(s.evictions, 1u);
  EXPECT_EQ(s.entries, 0u);
  EXPECT_EQ(s.building_bytes, 0u);
}

TEST(TreeCache, AfterStopMissesAreUnavailableButHitsAreServed) {
  TreeCache cache(TreeCacheOptions{});
  std::atomic<int> calls{0};
  ASSERT_TRUE(cache.Get(Key("s"), 4, Real("sphere", &calls), {}).ok());
  cache.Stop();
  EXPECT_TRUE(cache.Get(Key("s"), 4, Real("sphere", &calls), {}).ok());
  EXPECT_EQ(cache.Get(Key("t"), 4, Real("torus", &calls), {}).status().code(),
            absl::StatusCode::kUnavailable);
  EXPECT_EQ(calls.load(), 1);
}

}  // namespace
}  // namespace sfc
