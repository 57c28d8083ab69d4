// A TreeSource for the embedded Python sampler that keeps the last few
// trees, so repeated requests on one surface skip the build as the server's
// cache does (engine/tree_source.h).
// Thread-safety: thread-safe; the list is guarded by a mutex and builds run
// outside it.
#ifndef SFCSAMPLER_PYTHON_BINDINGS_RECENT_TREE_SOURCE_H_
#define SFCSAMPLER_PYTHON_BINDINGS_RECENT_TREE_SOURCE_H_

#include <list>
#include <memory>
#include <string>
#include <utility>

#include "absl/base/thread_annotations.h"
#include "absl/synchronization/mutex.h"
#include "engine/tree_source.h"

namespace sfc::python {

// Keeps the last `capacity` trees (by key and grade), so repeated requests on
// one surface skip the build, as the server's cache does. Exact matches only:
// a different grade builds afresh. Two threads asking for the same new tree
// at once may both build it (the result is the same tree).
class RecentTreeSource final : public TreeSource {
 public:
  explicit RecentTreeSource(size_t capacity) : capacity_(capacity) {}

  absl::StatusOr<TreeLookup> Get(const TreeKey& key, int grade, const TreeFactory& factory,
                                 const BuildControl& caller) override {
    const std::string id = key.HexWithGrade(grade) + "|" + key.canonical;
    if (capacity_ > 0) {
      absl::MutexLock lock(&mu_);
      for (auto it = recent_.begin(); it != recent_.end(); ++it) {
        if (it->first == id) {
          recent_.splice(recent_.begin(), recent_, it);
          return TreeLookup{it->second, TreeAs<CurveTree>(it->second.get()), true, false};
        }
      }
    }
    auto tree = factory.build(grade, caller);
    if (!tree.ok()) return tree.status();
    if (capacity_ > 0) {
      absl::MutexLock lock(&mu_);
      recent_.emplace_front(id, *tree);
      while (recent_.size() > capacity_) recent_.pop_back();
    }
    return TreeLookup{*tree, TreeAs<CurveTree>(tree->get()), false, false};
  }

 private:
  const size_t capacity_;
  absl::Mutex mu_;
  std::list<std::pair<std::string, std::shared_ptr<const AnyTree>>> recent_ ABSL_GUARDED_BY(mu_);
};

}  // namespace sfc::python

#endif  // SFCSAMPLER_PYTHON_BINDINGS_RECENT_TREE_SOURCE_H_
