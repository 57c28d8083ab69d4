#include "server/tree_cache.h"

#include <chrono>

#include "absl/strings/str_cat.h"

namespace sfc {

TreeCache::TreeCache(uint64_t budget_bytes, std::function<void(double)> on_build)
    : budget_bytes_(budget_bytes), on_build_(std::move(on_build)) {}

absl::StatusOr<TreeLookup> TreeCache::Get(const TreeKey& key, int grade, const TreeFactory& factory) {
  const std::string id = absl::StrCat(key.canonical, "#g", grade);
  std::promise<Result> promise;
  std::shared_future<Result> built_elsewhere;
  std::shared_ptr<const CurveTree> coarser;
  {
    absl::MutexLock lock(&mu_);
    if (auto it = entries_.find(id); it != entries_.end()) {
      lru_.splice(lru_.begin(), lru_, it->second.lru);
      ++stats_.hits;
      return TreeLookup{it->second.tree, true, false};
    }
    if (auto it = pending_.find(id); it != pending_.end()) {
      ++stats_.waits;
      built_elsewhere = it->second;
    } else {
      ++stats_.misses;
      if (auto g = grades_.find(key.canonical); g != grades_.end()) {
        auto below = g->second.lower_bound(grade);
        if (below != g->second.begin()) {
          coarser = entries_.at(absl::StrCat(key.canonical, "#g", *std::prev(below))).tree;
        }
      }
      pending_.emplace(id, promise.get_future().share());
    }
  }
  if (built_elsewhere.valid()) {
    const Result& tree = built_elsewhere.get();  // waits outside the lock
    if (!tree.ok()) return tree.status();
    return TreeLookup{*tree, false, false};
  }

  const auto start = std::chrono::steady_clock::now();
  Result tree = coarser ? factory.refine(*coarser, grade) : factory.build(grade);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  {
    absl::MutexLock lock(&mu_);
    pending_.erase(id);
    stats_.build_seconds += seconds;
    if (tree.ok()) {
      ++(coarser ? stats_.refinements : stats_.builds);
      lru_.push_front(id);
      const uint64_t bytes = (*tree)->bytes();
      entries_.emplace(id, Entry{*tree, bytes, key.canonical, grade, lru_.begin()});
      grades_[key.canonical].insert(grade);
      stats_.bytes += bytes;
      EvictOverBudget();
    }
  }
  if (on_build_) on_build_(seconds);
  promise.set_value(tree);
  if (!tree.ok()) return tree.status();
  return TreeLookup{*std::move(tree), false, coarser != nullptr};
}

void TreeCache::EvictOverBudget() {
  while (stats_.bytes > budget_bytes_ && !lru_.empty()) {
    auto it = entries_.find(lru_.back());
    stats_.bytes -= it->second.bytes;
    auto grades = grades_.find(it->second.canonical);
    grades->second.erase(it->second.grade);
    if (grades->second.empty()) grades_.erase(grades);
    entries_.erase(it);
    lru_.pop_back();
    ++stats_.evictions;
  }
}

TreeCacheStats TreeCache::stats() const {
  absl::MutexLock lock(&mu_);
  TreeCacheStats s = stats_;
  s.entries = entries_.size();
  return s;
}

}  // namespace sfc
