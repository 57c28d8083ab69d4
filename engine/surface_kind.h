// The one seam for kinds of surface (docs/ARCHITECTURE.md, "Adding a kind of
// surface"). A kind -- formula surfaces, CAD models, meshes -- is one object
// that resolves a spec into a tree key, a tree factory and a way to open
// cursors, and describes itself. The engine asks the registered kinds
// (kinds/registered_kinds.h) and knows none of them by name; a build without
// one of them simply has one kind fewer.
//
// Thread-safety: kinds are immutable and thread-safe; so is SurfaceKinds.
#ifndef SFCSAMPLER_ENGINE_SURFACE_KIND_H_
#define SFCSAMPLER_ENGINE_SURFACE_KIND_H_

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "absl/status/statusor.h"
#include "core/sequence.h"
#include "core/types/region.h"
#include "core/types/sample_batch.h"
#include "engine/batch_cursor.h"
#include "engine/engine_limits.h"
#include "engine/float32_range.h"
#include "engine/loaded_models.h"
#include "engine/model_source.h"
#include "engine/tree_source.h"
#include "request/sample_request.h"
#include "request/tree_key.h"

namespace sfc {

// What a kind may use while it resolves a spec.
struct KindContext {
  const EngineLimits* limits = nullptr;
  LoadedModels* loaded = nullptr;     // parsed models, parsed on its own threads
  std::function<absl::Status()> caller;  // asked while a parse waits (client gone, deadline)
};

// The part of the set a cursor covers, and how it is filled.
struct CursorSpec {
  uint64_t begin = 0, end = 0;  // indices [begin, end)
  Region region;
  SampleFields fields;
  int threads = 1;  // threads filling large batches
};

// Opens a cursor over `sequence` on the tree its kind made (`lookup`).
using CursorOpener = std::function<absl::StatusOr<std::unique_ptr<BatchCursor>>(
    const TreeLookup& lookup, Sequence sequence, const CursorSpec& spec)>;

// A spec as its kind resolved it.
struct ResolvedSurface {
  TreeKey key;
  TreeFactory factory;
  CursorOpener open_cursor;
  // Drops what was parsed for this spec when its tree could not be made (so a
  // next request does not keep it); empty when nothing was parsed.
  std::function<void()> forget;
  // What the kind measures of the samples' values before sampling, for a
  // float32 request's check (engine/float32_range.h); empty: nothing (each
  // batch is still checked).
  std::function<ValueExtent()> measure;
};

// What a kind is, for the engine's choices and messages.
struct KindInfo {
  std::string_view name;  // TreeInfo.kind: "surface", "model", "mesh"
  // For messages, after "needs": "a CAD model surface (step:, iges: or nurbs:)".
  std::string_view what;
  // The model formats it reads; empty: the specs that name no model file.
  std::vector<ModelFormat> formats;
  bool face_column = false;      // fills SampleFields::face
  bool triangle_column = false;  // fills SampleFields::triangle
  bool describes = false;        // Describe() lists its parts (sfcsampler inspect)
};

class SurfaceKind {
 public:
  virtual ~SurfaceKind() = default;
  virtual const KindInfo& info() const = 0;

  // The tree for `spec` (`model`: the stored file a model spec names, null
  // for a spec that names none), not yet built. Errors: INVALID_ARGUMENT for
  // a bad surface, model or density (the message says what to fix),
  // RESOURCE_EXHAUSTED for a parse out of budget, the caller's status.
  virtual absl::StatusOr<ResolvedSurface> Resolve(const TreeSpec& spec, const StoredModel* model,
                                                  const KindContext& context) const = 0;

  // Its parts as a table (only kinds with info().describes).
  virtual absl::StatusOr<std::string> Describe(const StoredModel& model,
                                               const KindContext& context) const {
    return absl::UnimplementedError("this kind of surface has no description");
  }
};

// The kinds a build has, asked in order.
class SurfaceKinds {
 public:
  explicit SurfaceKinds(std::vector<std::unique_ptr<const SurfaceKind>> kinds)
      : kinds_(std::move(kinds)) {}

  // The kind that samples `model` (nullopt: a spec naming no model file), or
  // null if this build has none.
  const SurfaceKind* For(const std::optional<ModelSpec>& model) const;
  // The first kind whose info passes `test`, or null.
  const SurfaceKind* Find(const std::function<bool(const KindInfo&)>& test) const;

 private:
  std::vector<std::unique_ptr<const SurfaceKind>> kinds_;
};

}  // namespace sfc

#endif  // SFCSAMPLER_ENGINE_SURFACE_KIND_H_
