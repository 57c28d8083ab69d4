// CAD models in the engine (issue 11): a model spec (step:FILE, iges:FILE,
// nurbs:FILE or FORMAT:sha256=HEX) with a density spec becomes a tree factory
// (cad/model_sampler.h: one tree per face, one curve through all faces) and,
// per request, a cursor with the face column. Built only with SFC_BUILD_CAD
// (SFC_HAVE_CAD).
//
// Densities are the catalogue's (core/density.h): uniform, gaussian, mean
// (from the kernel's exact second derivatives) and expr: in u, v (the face's
// own unit square) and x, y, z.
//
// Thread-safety: the functions are thread-safe.
#ifndef SFCSAMPLER_ENGINE_CAD_JOBS_H_
#define SFCSAMPLER_ENGINE_CAD_JOBS_H_

#include <functional>
#include <memory>
#include <string>

#include "absl/status/statusor.h"
#include "core/curve_tree.h"
#include "core/region.h"
#include "core/sample_batch.h"
#include "core/sequence.h"
#include "engine/batch_cursor.h"
#include "engine/loaded_models.h"
#include "engine/model_source.h"
#include "engine/tree_source.h"

namespace sfc {

struct CadTreeRecipe {
  std::string canonical_density;
  TreeFactory factory;
};

// Loads `model` (through `loaded`: on its parse threads, `caller` asked while
// the request waits) and returns how to build its trees. Errors:
// INVALID_ARGUMENT for a malformed or empty model (the message names the
// file, or FORMAT:sha256=HEX for an upload) or a bad density spec;
// RESOURCE_EXHAUSTED when the parse ran out of its CPU budget; caller's.
absl::StatusOr<CadTreeRecipe> CadTreeFor(const StoredModel& model, const std::string& density,
                                         const CurveTreeOptions& options, LoadedModels* loaded,
                                         const std::function<absl::Status()>& caller);

// A cursor over samples [begin, end) of `sequence` on the model trees held by
// `tree`. Errors as cad::ModelSampleCursor::Create.
absl::StatusOr<std::unique_ptr<BatchCursor>> CadCursor(const AnyTree& tree, Sequence sequence,
                                                       uint64_t begin, uint64_t end,
                                                       const Region& region,
                                                       const SampleFields& fields, int threads);

// The model's faces as a table (sfcsampler inspect): index, type, trimmed
// area, parameter box, orientation, and the curve order.
absl::StatusOr<std::string> DescribeCadModel(const StoredModel& model, LoadedModels* loaded);

}  // namespace sfc

#endif  // SFCSAMPLER_ENGINE_CAD_JOBS_H_
