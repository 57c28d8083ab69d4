// The tree cache's build jobs on their own: exceptions, waiters' checks and
// Stop(), with real trees of the catalogue's surfaces.
#include "server/tree_cache.h"

#include <atomic>
#include <chrono>
#include <memory>
#include <utility>
#include <new>
#include <stdexcept>
#include <thread>

#include "catalog/catalog.h"
#include "gtest/gtest.h"
#include "request/tree_key.h"

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

// The bytes of the sphere's and the torus's trees at `grade`, from a cache
// of their own.
std::pair<uint64_t, uint64_t> SphereAndTorusBytes(int grade) {
  TreeCache probe(TreeCacheOptions{});
  std::atomic<int> calls{0};
  return {(*probe.Get(Key("s"), grade, Real("sphere", &calls), {})).any->bytes(),
          (*probe.Get(Key("t"), grade, Real("torus", &calls), {})).any->bytes()};
}

TEST(TreeCache, AnEvictedTreeAStreamHoldsStaysCountedAndARequestTakesItBack) {
  const int grade = 16;
  const auto [sphere_bytes, torus_bytes] = SphereAndTorusBytes(grade);
  TreeCacheOptions options;
  options.budget_bytes = sphere_bytes + torus_bytes - 1;  // not both at once
  TreeCache cache(options);
  std::atomic<int> calls{0};
  auto held = cache.Get(Key("s"), grade, Real("sphere", &calls), {});  // a stream's tree
  ASSERT_TRUE(held.ok()) << held.status();
  // The torus's build evicts the sphere for room, but the stream still holds
  // it: it stays counted, and the build waits for it, until its request
  // gives up.
  std::atomic<bool> give_up{false};
  BuildControl caller;
  caller.check = [&]() -> absl::Status {
    return give_up ? absl::DeadlineExceededError("mine") : absl::OkStatus();
  };
  absl::StatusOr<TreeLookup> torus = absl::UnknownError("not yet");
  std::thread torus_request(
      [&] { torus = cache.Get(Key("t"), grade, Real("torus", &calls), caller); });
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (cache.stats().retired_waits == 0 && std::chrono::steady_clock::now() < until) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  TreeCacheStats s = cache.stats();
  EXPECT_GT(s.retired_waits, 0u);
  EXPECT_EQ(s.retired_trees, 1u);
  EXPECT_EQ(s.retired_bytes, sphere_bytes);
  EXPECT_EQ(s.entries, 0u);
  // A request for the held sphere takes it back: no second build.
  auto again = cache.Get(Key("s"), grade, Real("sphere", &calls), {});
  ASSERT_TRUE(again.ok()) << again.status();
  EXPECT_TRUE(again->cache_hit);
  EXPECT_EQ(again->any.get(), held->any.get());
  EXPECT_GE(cache.stats().revivals, 1u);
  give_up = true;
  torus_request.join();
  EXPECT_EQ(torus.status().code(), absl::StatusCode::kDeadlineExceeded);
  EXPECT_EQ(calls.load(), 2);  // the sphere once, the torus once
  cache.Stop();  // joins the builder, which stops at its next check
  s = cache.stats();
  EXPECT_EQ(s.builds_running, 0u);
  EXPECT_EQ(s.building_bytes, 0u);
}

TEST(TreeCache, ABuildWaitsForTheRoomAHeldEvictedTreeTakesUntilItsStreamEnds) {
  const int grade = 16;
  const auto [sphere_bytes, torus_bytes] = SphereAndTorusBytes(grade);
  TreeCacheOptions options;
  options.budget_bytes = sphere_bytes + torus_bytes - 1;
  TreeCache cache(options);
  std::atomic<int> calls{0};
  auto held = std::make_unique<absl::StatusOr<TreeLookup>>(
      cache.Get(Key("s"), grade, Real("sphere", &calls), {}));
  ASSERT_TRUE(held->ok());
  std::thread stream_ends([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    held.reset();
  });
  const auto start = std::chrono::steady_clock::now();
  auto torus = cache.Get(Key("t"), grade, Real("torus", &calls), {});
  const auto waited = std::chrono::steady_clock::now() - start;
  stream_ends.join();
  ASSERT_TRUE(torus.ok()) << torus.status();
  const TreeCacheStats s = cache.stats();
  EXPECT_GT(s.retired_waits, 0u);
  EXPECT_GE(waited, std::chrono::milliseconds(250));  // it did wait for the stream
  EXPECT_EQ(s.retired_bytes, 0u);
  EXPECT_EQ(s.bytes, torus_bytes);
}

}  // namespace
}  // namespace sfc
