// Meshes in the engine (issue 12): a mesh model spec (obj:FILE, ply:FILE or
// FORMAT:sha256=HEX) with a density spec becomes a tree key, a tree factory
// and, per request, a cursor. Built only with SFC_BUILD_MESH (SFC_HAVE_MESH).
//
// Densities on a mesh: uniform; gaussian:floor=F and mean:floor=F (|K| + F and
// |H| + F, from per-vertex discrete curvature, mesh/curvature.h); expr:BODY in
// x, y, z; vertex:NAME, the PLY vertex property NAME read as per-vertex
// weights and interpolated linearly over each triangle.
//
// Thread-safety: the functions are thread-safe.
#ifndef SFCSAMPLER_ENGINE_MESH_JOBS_H_
#define SFCSAMPLER_ENGINE_MESH_JOBS_H_

#include <functional>
#include <memory>
#include <string>

#include "absl/status/statusor.h"
#include "core/region.h"
#include "core/sample_batch.h"
#include "core/sequence.h"
#include "engine/batch_cursor.h"
#include "engine/loaded_models.h"
#include "engine/model_source.h"
#include "engine/tree_source.h"

namespace sfc {

struct MeshTreeRecipe {
  std::string canonical_density;
  TreeFactory factory;
};

// Parses `density` for a mesh, loads `model` (through `loaded`, on its parse
// threads; `caller` is asked while the request waits) as that
// density needs it, and returns how to build its tree. `tolerance` 0 takes
// the mesh tree's default. Errors: INVALID_ARGUMENT for a density meshes do
// not support, a malformed mesh (the message names the file), a missing
// weight property.
absl::StatusOr<MeshTreeRecipe> MeshTreeFor(const StoredModel& model, const std::string& density,
                                           double tolerance, uint64_t max_leaves,
                                           LoadedModels* loaded,
                                           const std::function<absl::Status()>& caller);

// A cursor over samples [begin, end) of `sequence` on the mesh tree held by
// `tree`, inside `region`, with `fields` (u, v are the barycentric
// coordinates of the triangle's corners 1 and 2; fields.triangle adds the
// triangle column); `threads` fill large batches. Errors as
// MeshSampleCursor::Create.
absl::StatusOr<std::unique_ptr<BatchCursor>> MeshCursor(const AnyTree& tree, Sequence sequence,
                                                        uint64_t begin, uint64_t end,
                                                        const Region& region,
                                                        const SampleFields& fields, int threads);

}  // namespace sfc

#endif  // SFCSAMPLER_ENGINE_MESH_JOBS_H_
