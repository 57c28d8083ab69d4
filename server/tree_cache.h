// The server's shared cache of curve trees (SERVICE.md, "Many jobs share one
// server").
//
// Keyed by the canonical text of everything that shapes a tree plus its grade.
// Concurrent requests for one key cause one build: the first builds, the
// others wait for its result. A miss for grade g refines the finest cached
// coarser grade of the same tree instead of building anew (the result is the
// same tree, see core/curve_tree.h). The cache holds at most budget_bytes of
// trees and evicts the least recently used; trees are shared as
// shared_ptr<const CurveTree>, so a stream keeps its tree alive through
// eviction.
//
// Thread-safety: thread-safe. Builds run outside the lock.
#ifndef SFCSAMPLER_SERVER_TREE_CACHE_H_
#define SFCSAMPLER_SERVER_TREE_CACHE_H_

#include <functional>
#include <future>
#include <list>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <unordered_map>

#include "absl/base/thread_annotations.h"
#include "absl/synchronization/mutex.h"
#include "engine/tree_source.h"

namespace sfc {

struct TreeCacheStats {
  uint64_t hits = 0;
  uint64_t misses = 0;
  uint64_t builds = 0;
  uint64_t refinements = 0;
  uint64_t evictions = 0;
  uint64_t waits = 0;  // requests that waited for another request's build
  uint64_t entries = 0;
  uint64_t bytes = 0;
  double build_seconds = 0;
};

class TreeCache final : public TreeSource {
 public:
  // `on_build`, if set, is called with the seconds of every build or
  // refinement (outside the lock).
  explicit TreeCache(uint64_t budget_bytes, std::function<void(double)> on_build = nullptr);
  TreeCache(const TreeCache&) = delete;
  TreeCache& operator=(const TreeCache&) = delete;

  absl::StatusOr<TreeLookup> Get(const TreeKey& key, int grade, const TreeFactory& factory) override
      ABSL_LOCKS_EXCLUDED(mu_);

  TreeCacheStats stats() const ABSL_LOCKS_EXCLUDED(mu_);
  uint64_t budget_bytes() const { return budget_bytes_; }

 private:
  using Result = absl::StatusOr<std::shared_ptr<const CurveTree>>;
  struct Entry {
    std::shared_ptr<const CurveTree> tree;
    uint64_t bytes;
    std::string canonical;
    int grade;
    std::list<std::string>::iterator lru;
  };

  void EvictOverBudget() ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_);

  // Constant after construction.
  const uint64_t budget_bytes_;
  const std::function<void(double)> on_build_;

  mutable absl::Mutex mu_;
  std::unordered_map<std::string, Entry> entries_ ABSL_GUARDED_BY(mu_);
  std::list<std::string> lru_ ABSL_GUARDED_BY(mu_);  // front: most recently used
  std::unordered_map<std::string, std::shared_future<Result>> pending_ ABSL_GUARDED_BY(mu_);
  std::map<std::string, std::set<int>> grades_ ABSL_GUARDED_BY(mu_);  // canonical -> cached grades
  TreeCacheStats stats_ ABSL_GUARDED_BY(mu_);
};

}  // namespace sfc

#endif  // SFCSAMPLER_SERVER_TREE_CACHE_H_
