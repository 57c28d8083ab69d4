// Where a request's curve tree comes from. The embedded CLI builds one per
// request (DirectTreeSource); the server shares them through its cache.
// Thread-safety: implementations must be thread-safe.
#ifndef SFCSAMPLER_ENGINE_TREE_SOURCE_H_
#define SFCSAMPLER_ENGINE_TREE_SOURCE_H_

#include <functional>
#include <memory>

#include "absl/status/statusor.h"
#include "core/curve_tree.h"
#include "engine/curve_tree_summary.h"
#include "request/tree_key.h"
#include "request/tree_summary.h"

namespace sfc {

// A built tree of any kind, as caches hold it: a CurveTree (catalogue and
// expression surfaces), a CAD model's trees or a mesh's tree. A cache needs
// only its size; the kind that made it knows its type (TypedTree<T>); every
// front door sees it through FillSummary.
class AnyTree {
 public:
  virtual ~AnyTree() = default;
  virtual uint64_t bytes() const = 0;
  virtual uint64_t leaves() const = 0;
  // S_M: the mass (area x density) along the whole curve.
  virtual double total_mass() const = 0;
  // Fills the fields of `out` that the tree knows (request/tree_summary.h):
  // leaves and bytes, and whatever its kind of tree adds. Leaves the
  // request's fields (kind, key, grade, cache) alone.
  virtual void FillSummary(TreeSummary* out) const = 0;
};

// A Tree as an AnyTree (a Tree has total_mass()). Each Tree type describes
// itself by a function
//   void FillTreeSummary(const Tree& tree, TreeSummary* out);
// in its own namespace (found by argument-dependent lookup, and declared
// before the TypedTree<Tree> is made), called after leaves and bytes are set:
// engine/curve_tree_summary.h for CurveTree, the mesh and CAD kinds for theirs.
template <typename Tree>
class TypedTree final : public AnyTree {
 public:
  TypedTree(std::shared_ptr<const Tree> tree, uint64_t bytes, uint64_t leaves)
      : tree_(std::move(tree)), bytes_(bytes), leaves_(leaves) {}
  uint64_t bytes() const override { return bytes_; }
  uint64_t leaves() const override { return leaves_; }
  double total_mass() const override { return tree_->total_mass(); }
  void FillSummary(TreeSummary* out) const override {
    out->leaves = leaves_;
    out->bytes = bytes_;
    FillTreeSummary(*tree_, out);
  }
  const std::shared_ptr<const Tree>& tree() const { return tree_; }

 private:
  std::shared_ptr<const Tree> tree_;
  uint64_t bytes_, leaves_;
};

// The Tree inside `any`, or null if it holds another kind.
template <typename Tree>
std::shared_ptr<const Tree> TreeAs(const AnyTree* any) {
  const auto* typed = dynamic_cast<const TypedTree<Tree>*>(any);
  return typed ? typed->tree() : nullptr;
}

// How to make the tree of a key: from scratch, or by refining a coarser one
// (which gives the same tree, see core/curve_tree.h; kinds of tree that
// cannot be refined leave `refine` empty and are built afresh). The functions
// own what they use: a shared build may run on another thread after the
// request that started it has gone.
struct TreeFactory {
  using Result = absl::StatusOr<std::shared_ptr<const AnyTree>>;
  std::function<Result(int grade, const BuildControl& control)> build;
  std::function<Result(const AnyTree& coarser, int grade, const BuildControl& control)> refine;
};

// Wraps a build's result as an AnyTree (for trees with bytes() and leaf_count()).
template <typename Tree>
TreeFactory::Result AsAnyTree(absl::StatusOr<std::shared_ptr<const Tree>> tree) {
  if (!tree.ok()) return tree.status();
  const uint64_t bytes = (*tree)->bytes(), leaves = (*tree)->leaf_count();
  return std::make_shared<const TypedTree<Tree>>(*std::move(tree), bytes, leaves);
}

struct TreeLookup {
  std::shared_ptr<const AnyTree> any;  // as its kind's own type: TreeAs<T>(any.get())
  bool cache_hit = false;              // the exact tree was cached
  bool refined = false;                // made by refining a cached coarser tree
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
    TreeLookup lookup;
    lookup.any = *std::move(tree);
    return lookup;
  }
};

}  // namespace sfc

#endif  // SFCSAMPLER_ENGINE_TREE_SOURCE_H_
