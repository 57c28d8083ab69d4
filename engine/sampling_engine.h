// Turns a SampleRequest into a validated sampling job: resolves the specs,
// checks every limit, gets the curve tree from a TreeSource and opens a
// cursor over the requested part of the set. Shared by the embedded CLI and
// the gRPC server.
//
// Thread-safety: SamplingEngine is thread-safe (it holds only constants and a
// thread-safe TreeSource). A Job is used by one thread at a time.
#ifndef SFCSAMPLER_ENGINE_SAMPLING_ENGINE_H_
#define SFCSAMPLER_ENGINE_SAMPLING_ENGINE_H_

#include <memory>

#include "absl/status/statusor.h"
#include "core/sampler.h"
#include "engine/batch_cursor.h"
#include "engine/loaded_models.h"
#include "engine/model_source.h"
#include "engine/sample_request.h"
#include "engine/tree_key.h"
#include "engine/tree_source.h"

namespace sfc {

// What a tree is over: a parametric surface (catalogue, expression; its
// CurveTree is lookup.tree), a triangle mesh or a CAD model (lookup.any holds
// its trees).
enum class TreeKind { kSurface, kMesh, kCadModel };

// "surface", "mesh", "model" (TreeInfo.kind).
const char* TreeKindName(TreeKind kind);

struct PreparedTree {
  TreeKey key;
  int grade = 0;
  TreeKind kind = TreeKind::kSurface;
  TreeLookup lookup;
  // kSurface only.
  std::shared_ptr<const Surface> surface;
  std::shared_ptr<const Density> density;
};

struct SamplingJob {
  PreparedTree tree;
  std::shared_ptr<const Sampler> sampler;  // kSurface only
  uint64_t begin = 0, end = 0;  // the resolved index range
  std::unique_ptr<BatchCursor> cursor;
};

class SamplingEngine {
 public:
  // `source` and `models` are not owned and must outlive the engine. `models`
  // resolves model specs (step:, obj:, ...): files for the embedded CLI, the
  // upload store for the server; null refuses model specs.
  SamplingEngine(EngineLimits limits, TreeSource* source, const ModelSource* models = nullptr);

  const EngineLimits& limits() const { return limits_; }

  // The tree for `spec`, fine enough for `count` samples. Errors:
  // INVALID_ARGUMENT (bad spec, count 0 or above max_count, surface or density
  // errors), RESOURCE_EXHAUSTED (tree budget).
  // `caller.check` is asked while the tree is built or waited for; its non-OK
  // status (client gone, deadline) ends the call with that status.
  absl::StatusOr<PreparedTree> Prepare(const TreeSpec& spec, uint64_t count,
                                       const BuildControl& caller = {}) const;

  // Validates `request` and opens its cursor. Errors as Prepare, plus
  // INVALID_ARGUMENT for a bad range, shard, region or tree_count.
  absl::StatusOr<SamplingJob> Start(const SampleRequest& request,
                                    const BuildControl& caller = {}) const;

  // The index range [begin, end) a request selects (before its region).
  static absl::StatusOr<std::pair<uint64_t, uint64_t>> ResolveRange(const SampleRequest& request);

  // The parsed models (for statistics, and to forget an evicted upload's).
  LoadedModels& loaded_models() const { return *loaded_; }

 private:
  absl::StatusOr<PreparedTree> PrepareModel(const ModelSpec& model, const TreeSpec& spec,
                                            uint64_t count, const BuildControl& caller) const;

 public:
  // The faces of the CAD model `spec` names, as a table (sfcsampler
  // inspect). INVALID_ARGUMENT for a spec that is not a CAD model.
  absl::StatusOr<std::string> DescribeModel(const std::string& spec) const;

 private:

  const EngineLimits limits_;
  TreeSource* const source_;
  const ModelSource* const models_;
  const std::unique_ptr<LoadedModels> loaded_;
};

}  // namespace sfc

#endif  // SFCSAMPLER_ENGINE_SAMPLING_ENGINE_H_
