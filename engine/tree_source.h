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
// (which gives the same tree, see core/curve_tree.h).
struct TreeFactory {
  std::function<absl::StatusOr<std::shared_ptr<const CurveTree>>(int grade)> build;
  std::function<absl::StatusOr<std::shared_ptr<const CurveTree>>(const CurveTree& coarser,
                                                                 int grade)>
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
  virtual absl::StatusOr<TreeLookup> Get(const TreeKey& key, int grade,
                                         const TreeFactory& factory) = 0;
};

// Builds every tree afresh; no sharing.
class DirectTreeSource final : public TreeSource {
 public:
  absl::StatusOr<TreeLookup> Get(const TreeKey& key, int grade, const TreeFactory& factory) override {
    auto tree = factory.build(grade);
    if (!tree.ok()) return tree.status();
    return TreeLookup{*std::move(tree), false, false};
  }
};

}  // namespace sfc

#endif  // SFCSAMPLER_ENGINE_TREE_SOURCE_H_
