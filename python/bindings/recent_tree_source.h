// A TreeSource for the embedded Python sampler that keeps the last few
// trees, so repeated requests on one surface skip the build as the server's
// cache does (engine/tree_source.h).
// Thread-safety: thread-safe; the list is guarded by a mutex and builds run
// outside it.
#ifndef SFCSAMPLER_PYTHON_BINDINGS_RECENT_TREE_SOURCE_H_
#define SFCSAMPLER_PYTHON_BINDINGS_RECENT_TREE_SOURCE_H_

#include <memory>
#include <string>

#include "absl/base/thread_annotations.h"
#include "absl/synchronization/mutex.h"
#include "base/lru.h"
#include "engine/tree_source.h"

namespace sfc::python {

// Keeps the last `capacity` trees (by key and grade), so repeated requests on
// one surface skip the build, as the server's cache does. Exact matches only:
// a different grade builds afresh. Two threads asking for the same new tree
// at once may both build it (the result is the same tree; the first kept
// stays).
class RecentTreeSource final : public TreeSource {
 public:
  explicit RecentTreeSource(size_t capacity) : capacity_(capacity) {}

  absl::StatusOr<TreeLookup> Get(const TreeKey& key, int grade, const TreeFactory& factory,
                                 const BuildControl& caller) override {
    const std::string id = key.HexWithGrade(grade) + "|" + key.canonical;
    if (capacity_ > 0) {
      absl::MutexLock lock(&mu_);
      if (const auto* kept = recent_.Touch(id)) {
        return TreeLookup{*kept, true, false};
      }
    }
    auto tree = factory.build(grade, caller);
    if (!tree.ok()) return tree.status();
    if (capacity_ > 0) {
      absl::MutexLock lock(&mu_);
      recent_.Insert(id, *tree, 1);
      while (recent_.size() > capacity_) recent_.PopLeastRecent();
    }
    return TreeLookup{*tree, false, false};
  }

 private:
  const size_t capacity_;
  absl::Mutex mu_;
  Lru<std::string, std::shared_ptr<const AnyTree>> recent_ ABSL_GUARDED_BY(mu_);  // by id
};

}  // namespace sfc::python

#endif  // SFCSAMPLER_PYTHON_BINDINGS_RECENT_TREE_SOURCE_H_
