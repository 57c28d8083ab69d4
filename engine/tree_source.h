// Where a request's curve tree comes from. The embedded CLI builds one per
// request (DirectTreeSource); the server shares them through its cache.
// Thread-safety: implementations must be thread-safe.
#ifndef SFCSAMPLER_ENGINE_TREE_SOURCE_H_
#define SFCSAMPLER_ENGINE_TREE_SOURCE_H_

#include <functional>
#include <memory>

#include "absl/status/statusor.h"
#include "core/curve_tree.h"
#include "engine/tree_key.h"

namespace sfc {

// How to make the tree of a key: from scratch, or by refining a coarser one
// (which gives the same tree, see core/curve_tree.h). The functions own what
// they use: a shared build may run on another thread after the request that
// started it has gone.
struct TreeFactory {
  std::function<absl::StatusOr<std::shared_ptr<const CurveTree>>(int grade,
                                                                 const BuildControl& control)>
      build;
  std::function<absl::StatusOr<std::shared_ptr<const CurveTree>>(
      const CurveTree& coarser, int grade, const BuildControl& control)>
      refine;
};

struct TreeLookup {
  std::shared_ptr<const CurveTree> tree;
  bool cache_hit = false;    // the exact tree was cached
  bool refined = false;      // made by refining a cached coarser tree
};

class TreeSource {
 public:
  virtual ~TreeSource() = default;
  // The tree of `key` at `grade`. `caller.check` says whether the request
  // still wants it (client gone, deadline passed): while it waits for a build,
  // a non-OK answer makes Get return that status at once.
  virtual absl::StatusOr<TreeLookup> Get(const TreeKey& key, int grade, const TreeFactory& factory,
                                         const BuildControl& caller) = 0;
};

// Builds every tree afresh on the caller's thread; no sharing.
class DirectTreeSource final : public TreeSource {
 public:
  absl::StatusOr<TreeLookup> Get(const TreeKey& key, int grade, const TreeFactory& factory,
                                 const BuildControl& caller) override {
    auto tree = factory.build(grade, caller);
    if (!tree.ok()) return tree.status();
    return TreeLookup{*std::move(tree), false, false};
  }
};

}  // namespace sfc

#endif  // SFCSAMPLER_ENGINE_TREE_SOURCE_H_
