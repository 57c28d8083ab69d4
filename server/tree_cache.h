// The server's shared cache of curve trees (docs/SERVICE.md, "Many jobs share one
// server").
//
// Keyed by the canonical text of everything that shapes a tree plus its grade.
// A miss becomes a build job; concurrent requests for one key share that job
// (one build). A miss for grade g refines the finest cached coarser grade of
// the same tree instead of building anew (the result is the same tree, see
// core/curve_tree.h). The cache holds at most budget_bytes of trees and evicts
// the least recently used; trees (of any kind: engine/tree_source.h AnyTree) are shared as
// shared_ptrs, so a stream keeps its tree alive through eviction. Such an evicted tree still takes
// memory: it stays counted against budget_bytes ("retired") until the last holder lets go, and a
// request for it takes it back into the cache instead of building a second copy.
//
// Builds are bounded:
//  - they run on max_concurrent_builds threads of the cache's own; at most
//    max_queued_builds more wait for a thread, past that a miss is
//    RESOURCE_EXHAUSTED;
//  - every request waits with its own check (client gone, deadline), and a
//    build that no request wants any more stops at its next BuildControl
//    check; Stop() (shutdown) stops them all;
//  - trees being built count against budget_bytes as they grow: cached trees
//    are evicted to make room, a build that would push the builds in
//    progress past the budget on their own fails with RESOURCE_EXHAUSTED, and
//    one that needs room that retired trees hold waits (with its checks) for
//    their streams to end, so cached, retired and growing trees stay within
//    the budget;
//  - a build that failed (budget, bad surface) is remembered for
//    failure_ttl_seconds, so identical requests get its error at once instead
//    of repeating it;
//  - an exception thrown by a build becomes its status; no key stays pending.
//
// Thread-safety: thread-safe.
#ifndef SFCSAMPLER_SERVER_TREE_CACHE_H_
#define SFCSAMPLER_SERVER_TREE_CACHE_H_

#include <chrono>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <thread>
#include <unordered_map>
#include <vector>

#include "absl/base/thread_annotations.h"
#include "absl/synchronization/mutex.h"
#include "base/lru.h"
#include "engine/tree_source.h"

namespace sfc {

struct TreeCacheOptions {
  uint64_t budget_bytes = uint64_t{1} << 30;  // trees kept, LRU past it
  int max_concurrent_builds = 2;              // builder threads, >= 1
  int max_queued_builds = 16;                 // builds waiting for a thread, >= 0
  double failure_ttl_seconds = 60;            // how long a failed build is remembered, >= 0
};

struct TreeCacheStats {
  uint64_t hits = 0;
  uint64_t misses = 0;
  uint64_t builds = 0;
  uint64_t refinements = 0;
  uint64_t evictions = 0;
  uint64_t waits = 0;  // requests that joined another request's build
  uint64_t entries = 0;
  uint64_t bytes = 0;           // of cached trees
  uint64_t building_bytes = 0;  // of trees being built, now
  uint64_t retired_bytes = 0;   // of evicted trees that requests still hold, now
  uint64_t retired_trees = 0;   // now
  uint64_t revivals = 0;        // retired trees taken back into the cache by a request
  uint64_t retired_waits = 0;   // times a build waited for retired trees to be let go
  double build_seconds = 0;
  uint64_t builds_running = 0;    // now
  uint64_t builds_queued = 0;     // now, waiting for a builder thread
  uint64_t builds_stopped = 0;    // abandoned by every request, or stopped by shutdown
  uint64_t builds_failed = 0;     // ended with an error (remembered for failure_ttl_seconds)
  uint64_t builds_rejected = 0;   // misses turned away because the queue was full
  uint64_t failure_hits = 0;      // requests answered from the remembered failures
};

class TreeCache final : public TreeSource {
 public:
  // `on_build`, if set, is called with the seconds of every finished build or
  // refinement (outside the lock).
  explicit TreeCache(const TreeCacheOptions& options,
                     std::function<void(double)> on_build = nullptr);
  ~TreeCache() override;  // Stop()s
  TreeCache(const TreeCache&) = delete;
  TreeCache& operator=(const TreeCache&) = delete;

  absl::StatusOr<TreeLookup> Get(const TreeKey& key, int grade, const TreeFactory& factory,
                                 const BuildControl& caller) override ABSL_LOCKS_EXCLUDED(mu_);

  // Stops every build (running ones at their next check, queued ones at once:
  // their requests get UNAVAILABLE) and the builder threads; later misses are
  // UNAVAILABLE. Idempotent; call from one thread at a time.
  void Stop() ABSL_LOCKS_EXCLUDED(mu_);

  TreeCacheStats stats() const ABSL_LOCKS_EXCLUDED(mu_);
  const TreeCacheOptions& options() const { return options_; }
  uint64_t budget_bytes() const { return options_.budget_bytes; }

 private:
  using Clock = std::chrono::steady_clock;
  using Result = TreeFactory::Result;
  // A cached tree; its bytes are its cost in cached_.
  struct Entry {
    std::shared_ptr<const AnyTree> tree;
    std::string canonical;
    int grade;
  };
  // One build or refinement, shared by every request that waits for it.
  struct Job {
    std::string id, canonical;
    int grade = 0;
    TreeFactory factory;                       // the first requester's; owns its data
    std::shared_ptr<const AnyTree> coarser;    // refine this one, if set
    int coarser_grade = 0;
    // Guarded by the cache's mu_.
    int waiters = 0;
    uint64_t charged = 0;  // bytes the build holds, as it last said
    bool started = false, done = false;
    Result result;
  };
  // An evicted tree that something (a stream, a refinement) still holds.
  struct Retired {
    std::weak_ptr<const AnyTree> tree;
    const AnyTree* raw;  // identity, for a refinement's own coarser tree
    uint64_t bytes;
    std::string canonical;
    int grade;
  };
  struct Failure {
    absl::Status status;
    Clock::time_point when;
  };

  void BuilderLoop() ABSL_LOCKS_EXCLUDED(mu_);
  void Run(Job& job) ABSL_LOCKS_EXCLUDED(mu_);
  void Finish(Job& job, Result result, double seconds) ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_);
  // Why a build should stop now, or OK.
  absl::Status BuildCheck(const Job& job) const ABSL_LOCKS_EXCLUDED(mu_);
  // Counts `bytes` for a growing build; evicts for room or refuses.
  absl::Status Charge(Job& job, uint64_t bytes) ABSL_LOCKS_EXCLUDED(mu_);
  void EvictOverBudget() ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_);
  // Drops the retired trees nobody holds any more from the count.
  void PruneRetired() ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_);
  // Caches a tree as the most recently used, counted in bytes.
  void Insert(const std::string& id, std::shared_ptr<const AnyTree> tree, uint64_t bytes,
              const std::string& canonical, int grade) ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_);
  void Forget(const std::shared_ptr<Job>& job) ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_);

  // Constant after construction.
  const TreeCacheOptions options_;
  const std::function<void(double)> on_build_;

  mutable absl::Mutex mu_;
  Lru<std::string, Entry> cached_ ABSL_GUARDED_BY(mu_);  // by id, costing bytes
  std::unordered_map<std::string, std::shared_ptr<Job>> pending_ ABSL_GUARDED_BY(mu_);
  std::deque<std::shared_ptr<Job>> queue_ ABSL_GUARDED_BY(mu_);  // not yet started
  std::map<std::string, std::set<int>> grades_ ABSL_GUARDED_BY(mu_);  // canonical -> cached grades
  std::unordered_map<std::string, Failure> failures_ ABSL_GUARDED_BY(mu_);
  std::unordered_map<std::string, Retired> retired_ ABSL_GUARDED_BY(mu_);  // by id
  bool stopping_ ABSL_GUARDED_BY(mu_) = false;
  TreeCacheStats stats_ ABSL_GUARDED_BY(mu_);  // entries and bytes: see cached_
  std::vector<std::thread> builders_;  // started in the constructor, joined by Stop()
};

}  // namespace sfc

#endif  // SFCSAMPLER_SERVER_TREE_CACHE_H_
