#include "engine/sampling_engine.h"

#include "absl/strings/str_format.h"
#include "catalog/catalog.h"
#include "core/status_macros.h"
#include "engine/model_source.h"
#ifdef SFC_HAVE_MESH
#include "engine/mesh_jobs.h"
#endif
#ifdef SFC_HAVE_CAD
#include "engine/cad_jobs.h"
#endif

namespace sfc {

SamplingEngine::SamplingEngine(EngineLimits limits, TreeSource* source, const ModelSource* models)
    : limits_(limits),
      source_(source),
      models_(models),
      loaded_(std::make_unique<LoadedModels>([&limits] {
        LoadedModelsOptions o;
        o.budget_bytes = limits.parsed_model_bytes;
        o.parse_threads = limits.model_parse_threads;
        o.max_queued_parses = limits.max_queued_parses;
        o.parse_seconds = limits.model_parse_seconds;
        o.failure_ttl_seconds = limits.parse_failure_ttl_seconds;
        return o;
      }())) {}

const char* TreeKindName(TreeKind kind) {
  switch (kind) {
    case TreeKind::kSurface: return "surface";
    case TreeKind::kMesh: return "mesh";
    case TreeKind::kCadModel: return "model";
  }
  return "surface";
}

absl::StatusOr<PreparedTree> SamplingEngine::PrepareModel(const ModelSpec& model,
                                                          const TreeSpec& spec, uint64_t count,
                                                          const BuildControl& caller) const {
  const bool mesh = model.format == ModelFormat::kObj || model.format == ModelFormat::kPly;
#ifndef SFC_HAVE_MESH
  if (mesh) {
    return absl::UnimplementedError(
        "this build of sfcsampler has no mesh support (configured with SFC_BUILD_MESH=OFF)");
  }
#endif
#ifndef SFC_HAVE_CAD
  if (!mesh) {
    return absl::UnimplementedError(
        "this build of sfcsampler has no CAD support (configured with SFC_BUILD_CAD=OFF)");
  }
#endif
  if (!models_) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "\"%s\" names a model, and this engine has no model source to read it from",
        spec.surface));
  }
  ASSIGN_OR_RETURN(const StoredModel stored, models_->Resolve(model));
  PreparedTree prepared;
  prepared.grade = CurveTree::GradeFor(count);
  TreeFactory factory;
  if (mesh) {
#ifdef SFC_HAVE_MESH
    ASSIGN_OR_RETURN(MeshTreeRecipe recipe,
                     MeshTreeFor(stored, spec.density, spec.options.tolerance,
                                 limits_.max_tree_leaves, loaded_.get(), caller.check));
    CurveTreeOptions options;  // a mesh's curve has no options but the tolerance
    options.tolerance = spec.options.tolerance;
    prepared.kind = TreeKind::kMesh;
    prepared.key = MakeTreeKey(stored.Spec(), recipe.canonical_density, options);
    factory = std::move(recipe.factory);
#endif
  } else {
#ifdef SFC_HAVE_CAD
    CurveTreeOptions options = spec.options;
    options.max_leaves = limits_.max_tree_leaves;
    ASSIGN_OR_RETURN(CadTreeRecipe recipe,
                     CadTreeFor(stored, spec.density, options, loaded_.get(), caller.check));
    prepared.kind = TreeKind::kCadModel;
    prepared.key = MakeTreeKey(stored.Spec(), recipe.canonical_density, options);
    factory = std::move(recipe.factory);
#endif
  }
  auto lookup = source_->Get(prepared.key, prepared.grade, factory, caller);
  if (!lookup.ok()) {
    // A model whose tree failed is not kept for a next request (its memory
    // goes once no request holds it); a request that left keeps it.
    const absl::StatusCode code = lookup.status().code();
    if (code != absl::StatusCode::kCancelled && code != absl::StatusCode::kDeadlineExceeded &&
        code != absl::StatusCode::kUnavailable) {
      loaded_->ForgetModel(stored.sha256);
    }
    return lookup.status();
  }
  prepared.lookup = *std::move(lookup);
  return prepared;
}

absl::StatusOr<std::string> SamplingEngine::DescribeModel(const std::string& spec) const {
  ASSIGN_OR_RETURN(const std::optional<ModelSpec> model, ParseModelSpec(spec));
  if (!model || model->format == ModelFormat::kObj || model->format == ModelFormat::kPly) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "\"%s\" is not a CAD model; inspect takes step:FILE, iges:FILE or nurbs:FILE", spec));
  }
#ifndef SFC_HAVE_CAD
  return absl::UnimplementedError(
      "this build of sfcsampler has no CAD support (configured with SFC_BUILD_CAD=OFF)");
#else
  if (!models_) return absl::InvalidArgumentError("this engine has no model source");
  ASSIGN_OR_RETURN(const StoredModel stored, models_->Resolve(*model));
  return DescribeCadModel(stored, loaded_.get());
#endif
}

absl::StatusOr<PreparedTree> SamplingEngine::Prepare(const TreeSpec& spec, uint64_t count,
                                                     const BuildControl& caller) const {
  if (count == 0) return absl::InvalidArgumentError("count must be >= 1");
  if (count > limits_.max_count) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "count %d is above this server's limit of %d samples per request (max_count); split the "
        "request into index ranges or shards",
        count, limits_.max_count));
  }
  for (const auto* text : {&spec.surface, &spec.density}) {
    if (text->size() > limits_.max_spec_length) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "a surface or density spec of %d characters is longer than the limit of %d "
          "(max_spec_length)",
          text->size(), limits_.max_spec_length));
    }
  }
  ASSIGN_OR_RETURN(const std::optional<ModelSpec> model, ParseModelSpec(spec.surface));
  if (model) return PrepareModel(*model, spec, count, caller);
  ASSIGN_OR_RETURN(SurfaceFromSpec surface, MakeSurface(spec.surface));
  ASSIGN_OR_RETURN(DensityFromSpec density, MakeDensity(spec.density));
  CurveTreeOptions options = spec.options;
  options.max_leaves = limits_.max_tree_leaves;  // the server sets the budget, not the request

  PreparedTree prepared;
  prepared.key = MakeTreeKey(surface.canonical, density.canonical, options);
  prepared.grade = CurveTree::GradeFor(count);
  prepared.surface = surface.surface;
  prepared.density = density.density;
  TreeFactory factory;
  factory.build = [surface = prepared.surface, density = prepared.density, options](
                      int grade, const BuildControl& control) -> TreeFactory::Result {
    return AsAnyTree(CurveTree::Build(*surface, *density, options, grade, control));
  };
  factory.refine = [surface = prepared.surface, density = prepared.density](
                       const AnyTree& coarser, int grade,
                       const BuildControl& control) -> TreeFactory::Result {
    const auto tree = TreeAs<CurveTree>(&coarser);
    if (!tree) return absl::InternalError("refining a tree of another kind");
    return AsAnyTree(tree->Refined(*surface, *density, grade, control));
  };
  ASSIGN_OR_RETURN(prepared.lookup, source_->Get(prepared.key, prepared.grade, factory, caller));
  return prepared;
}

absl::StatusOr<std::pair<uint64_t, uint64_t>> SamplingEngine::ResolveRange(
    const SampleRequest& request) {
  const uint64_t n = request.count;
  if (request.shard_count > 0) {
    if (request.begin != 0 || request.end != 0) {
      return absl::InvalidArgumentError("ask for either an index range or a shard, not both");
    }
    if (request.shard_index >= request.shard_count) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "shard index %d must be below the shard count %d", request.shard_index, request.shard_count));
    }
    // Shard i of K holds [floor(iN/K), floor((i+1)N/K)).
    auto bound = [&](uint64_t i) {
      return static_cast<uint64_t>(static_cast<unsigned __int128>(i) * n / request.shard_count);
    };
    return std::make_pair(bound(request.shard_index), bound(request.shard_index + 1));
  }
  const uint64_t end = request.end == 0 ? n : request.end;
  if (request.begin > end || end > n) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "the index range [%d, %d) is not inside the set of %d samples; it needs begin <= end <= "
        "count",
        request.begin, end, n));
  }
  return std::make_pair(request.begin, end);
}

absl::StatusOr<SamplingJob> SamplingEngine::Start(const SampleRequest& request,
                                                  const BuildControl& caller) const {
  if (request.count == 0) return absl::InvalidArgumentError("count must be >= 1");
  if (request.count > limits_.max_count) {
    // Checked before any tree is built for it.
    return absl::InvalidArgumentError(absl::StrFormat(
        "count %d is above this server's limit of %d samples per request (max_count); split the "
        "request into index ranges or shards",
        request.count, limits_.max_count));
  }
  const bool radical_inverse = request.sequence == SequenceKind::kVanDerCorput ||
                               request.sequence == SequenceKind::kProgressive;
  if (radical_inverse && request.count > (uint64_t{1} << 32)) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "the %s sequence supports at most 2^32 samples", SequenceName(request.sequence)));
  }
  ASSIGN_OR_RETURN(const auto range, ResolveRange(request));
  if (!Sequence(request.sequence, 1, 0).monotone() &&
      range.second - range.first > limits_.max_sorted_range) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "the %s sequence is sorted into curve order per request, so a request may cover at most "
        "%d samples (max_sorted_range); ask for index ranges of that size",
        SequenceName(request.sequence), limits_.max_sorted_range));
  }
  RETURN_IF_ERROR(request.region.Validate());
  if (request.fields.face || request.fields.triangle) {
    ASSIGN_OR_RETURN(const std::optional<ModelSpec> model, ParseModelSpec(request.tree.surface));
    const bool mesh = model && (model->format == ModelFormat::kObj || model->format == ModelFormat::kPly);
    if (request.fields.face && (!model || mesh)) {
      return absl::InvalidArgumentError(
          "the face column needs a CAD model surface (step:, iges: or nurbs:)");
    }
    if (request.fields.triangle && !mesh) {
      return absl::InvalidArgumentError("the triangle column needs a mesh surface (obj: or ply:)");
    }
  }
  if (request.tree_count != 0 && request.tree_count < request.count) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "tree_count %d is below count %d: the tree must be sized for at least the whole set "
        "(leave tree_count 0 to size it for count, or set it to the final size of a progressive "
        "set)",
        request.tree_count, request.count));
  }
  const uint64_t tree_count = request.tree_count == 0 ? request.count : request.tree_count;
  SamplingJob job;
  ASSIGN_OR_RETURN(job.tree, Prepare(request.tree, tree_count, caller));
  job.begin = range.first;
  job.end = range.second;
  Sequence sequence(request.sequence, request.count, request.seed);
#ifdef SFC_HAVE_MESH
  if (job.tree.kind == TreeKind::kMesh) {
    ASSIGN_OR_RETURN(job.cursor, MeshCursor(*job.tree.lookup.any, std::move(sequence), job.begin,
                                            job.end, request.region, request.fields,
                                            limits_.generation_threads));
    return job;
  }
#endif
#ifdef SFC_HAVE_CAD
  if (job.tree.kind == TreeKind::kCadModel) {
    ASSIGN_OR_RETURN(job.cursor, CadCursor(*job.tree.lookup.any, sequence, job.begin, job.end,
                                           request.region, request.fields,
                                           limits_.generation_threads));
    return job;
  }
#endif
  job.sampler = std::make_shared<const Sampler>(job.tree.lookup.tree, job.tree.surface,
                                                job.tree.density, std::move(sequence));
  ASSIGN_OR_RETURN(std::unique_ptr<SampleCursor> cursor,
                   SampleCursor::Create(job.sampler, job.begin, job.end, request.region,
                                        request.fields, limits_.generation_threads));
  job.cursor = std::make_unique<SurfaceBatchCursor>(std::move(cursor));
  return job;
}

}  // namespace sfc
