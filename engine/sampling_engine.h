// Turns a SampleRequest into a validated sampling job: checks every limit,
// has the spec's kind of surface (engine/surface_kind.h) resolve it, gets the
// tree from a TreeSource and opens the kind's cursor over the requested part
// of the set. Shared by the embedded CLI, the gRPC server and Python.
//
// Thread-safety: SamplingEngine is thread-safe (it holds only constants and a
// thread-safe TreeSource). A Job is used by one thread at a time.
#ifndef SFCSAMPLER_ENGINE_SAMPLING_ENGINE_H_
#define SFCSAMPLER_ENGINE_SAMPLING_ENGINE_H_

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "absl/status/statusor.h"
#include "engine/batch_cursor.h"
#include "engine/engine_limits.h"
#include "engine/loaded_models.h"
#include "engine/model_source.h"
#include "engine/surface_kind.h"
#include "engine/tree_source.h"
#include "request/sample_request.h"
#include "request/stream_options.h"
#include "request/tree_key.h"
#include "request/tree_summary.h"

namespace sfc {

struct PreparedTree {
  TreeKey key;
  int grade = 0;
  std::string_view kind = "surface";  // its SurfaceKind's name: TreeInfo.kind
  TreeLookup lookup;
  CursorOpener open_cursor;              // how its kind samples it
  std::function<ValueExtent()> measure;  // ResolvedSurface::measure
};

// The summary of `tree` (request/tree_summary.h): its request's fields, then
// the tree's own (AnyTree::FillSummary), whatever its kind. The one place a
// prepared tree becomes a summary, for the wire, the CLI and Python alike.
TreeSummary SummarizeTree(const PreparedTree& tree);

struct SamplingJob {
  PreparedTree tree;
  uint64_t begin = 0, end = 0;  // the resolved index range
  std::unique_ptr<BatchCursor> cursor;
};

class SamplingEngine {
 public:
  // `kinds` (usually kinds/registered_kinds.h's), `source` and `models` are
  // not owned and must outlive the engine. `models` resolves model specs
  // (step:, obj:, ...): files for the embedded CLI, the upload store for the
  // server; null refuses model specs.
  SamplingEngine(const SurfaceKinds& kinds, EngineLimits limits, TreeSource* source,
                 const ModelSource* models = nullptr);

  const EngineLimits& limits() const { return limits_; }

  // The tree for `spec`, fine enough for `count` samples. Errors:
  // INVALID_ARGUMENT (bad spec, count 0 or above max_set_count, surface or density
  // errors), RESOURCE_EXHAUSTED (tree budget).
  // `caller.check` is asked while the tree is built or waited for; its non-OK
  // status (client gone, deadline) ends the call with that status.
  absl::StatusOr<PreparedTree> Prepare(const TreeSpec& spec, uint64_t count,
                                       const BuildControl& caller = {}) const;

  // The checks of `request` that need no tree (count, range, sequence,
  // region, columns), which Start makes first: INVALID_ARGUMENT as Start's.
  // For a front door that reserves memory for the request between the two.
  absl::Status CheckRequest(const SampleRequest& request) const;

  // Validates `request` and opens its cursor. Errors as Prepare, plus
  // INVALID_ARGUMENT for a bad range, shard, region or tree_count. A blue
  // set's relaxation asks `caller.check` too, and stops with its status.
  // For `precision` float32, INVALID_ARGUMENT too when the kind's measure of
  // the values shows a column float32 cannot hold, and the cursor ends the
  // job likewise at the first value it would make infinite
  // (engine/float32_range.h): the one place every front door checks it.
  absl::StatusOr<SamplingJob> Start(const SampleRequest& request, const BuildControl& caller = {},
                                    ColumnPrecision precision = ColumnPrecision::kFloat64) const;

  // The parsed models (for statistics, and to forget an evicted upload's).
  LoadedModels& loaded_models() const { return *loaded_; }

  // The parts of the model `spec` names, as a table (sfcsampler inspect: a
  // CAD model's faces). INVALID_ARGUMENT for a spec whose kind has no
  // description.
  absl::StatusOr<std::string> DescribeModel(const std::string& spec) const;

 private:
  // The kind that samples `spec`, and the stored model it names (if any).
  struct SpecKind {
    const SurfaceKind* kind = nullptr;
    std::optional<StoredModel> model;
  };
  absl::StatusOr<SpecKind> KindOf(const std::string& spec) const;
  // INVALID_ARGUMENT for a count (N) of 0 or past limits_.max_set_count.
  absl::Status CheckCount(uint64_t count) const;
  KindContext Context(const BuildControl& caller) const;

  const SurfaceKinds& kinds_;
  const EngineLimits limits_;
  TreeSource* const source_;
  const ModelSource* const models_;
  const std::unique_ptr<LoadedModels> loaded_;
};

}  // namespace sfc

#endif  // SFCSAMPLER_ENGINE_SAMPLING_ENGINE_H_
