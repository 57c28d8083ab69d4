#include "engine/sampling_engine.h"

#include "absl/strings/str_format.h"
#include "base/status_macros.h"
#include "engine/blue_sequence.h"
#include "engine/float32_range.h"
#include "engine/model_source.h"
#include "request/index_range.h"
#include "request/tree_count.h"

namespace sfc {
namespace {

// OK if `kind` fills the kind-specific column `fills` (&KindInfo::face_column,
// ...), else which kind of surface to ask it of.
absl::Status CheckColumn(const SurfaceKinds& kinds, const SurfaceKind* kind, bool KindInfo::*fills,
                         const char* column) {
  if (kind && kind->info().*fills) return absl::OkStatus();
  const SurfaceKind* filling = kinds.Find([fills](const KindInfo& i) { return i.*fills; });
  return absl::InvalidArgumentError(absl::StrFormat(
      "the %s column needs %s", column,
      filling ? filling->info().what : "a kind of surface this build does not have"));
}

}  // namespace

SamplingEngine::SamplingEngine(const SurfaceKinds& kinds, EngineLimits limits, TreeSource* source,
                               const ModelSource* models)
    : kinds_(kinds),
      limits_(limits),
      source_(source),
      models_(models),
      loaded_(std::make_unique<LoadedModels>([&limits] {
        LoadedModelsOptions o;
        o.budget_bytes = limits.parsed_model_bytes;
        o.working_budget_bytes = limits.parse_memory_bytes;
        o.parse_threads = limits.model_parse_threads;
        o.max_queued_parses = limits.max_queued_parses;
        o.parse_seconds = limits.model_parse_seconds;
        o.failure_ttl_seconds = limits.parse_failure_ttl_seconds;
        o.fresh_seconds = limits.model_parse_fresh_seconds;
        o.max_long_parses = limits.max_long_parses;
        o.max_queue_wait_seconds = limits.max_parse_queue_seconds;
        return o;
      }())) {}

KindContext SamplingEngine::Context(const BuildControl& caller) const {
  KindContext context;
  context.limits = &limits_;
  context.loaded = loaded_.get();
  context.caller = caller.check;
  return context;
}

absl::StatusOr<SamplingEngine::SpecKind> SamplingEngine::KindOf(const std::string& spec) const {
  ASSIGN_OR_RETURN(const std::optional<ModelSpec> model, ParseModelSpec(spec));
  SpecKind out;
  out.kind = kinds_.For(model);
  if (!out.kind) {
    return absl::UnimplementedError(absl::StrFormat(
        "this build of sfcsampler has no kind of surface for %s specs (it was configured "
        "without it: SFC_BUILD_CAD=OFF or SFC_BUILD_MESH=OFF, as tools/sample.sh builds on a "
        "fresh clone); bash tools/build.sh builds every kind",
        model ? absl::StrFormat("%s:", ModelFormatName(model->format)) : "formula"));
  }
  if (!model) return out;
  if (!models_) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "\"%s\" names a model, and this engine has no model source to read it from", spec));
  }
  ASSIGN_OR_RETURN(out.model, models_->Resolve(*model));
  return out;
}

absl::StatusOr<std::string> SamplingEngine::DescribeModel(const std::string& spec) const {
  const SurfaceKind* describing = kinds_.Find([](const KindInfo& i) { return i.describes; });
  ASSIGN_OR_RETURN(const std::optional<ModelSpec> model, ParseModelSpec(spec));
  const SurfaceKind* kind = kinds_.For(model);
  if (!describing) {
    return absl::UnimplementedError(
        "this build of sfcsampler has no kind of surface that inspect describes (configured with "
        "SFC_BUILD_CAD=OFF)");
  }
  if (!model || !kind || !kind->info().describes) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "\"%s\" is not %s, which inspect describes", spec, describing->info().what));
  }
  ASSIGN_OR_RETURN(const SpecKind found, KindOf(spec));
  return kind->Describe(*found.model, Context({}));
}

TreeSummary SummarizeTree(const PreparedTree& t) {
  TreeSummary s;
  s.kind = std::string(t.kind);
  s.key = t.key.Hex();
  s.key_with_grade = t.key.HexWithGrade(t.grade);
  s.canonical = t.key.canonical;
  s.grade = t.grade;
  s.cache_hit = t.lookup.cache_hit;
  s.refined = t.lookup.refined;
  t.lookup.any->FillSummary(&s);
  return s;
}

absl::Status SamplingEngine::CheckCount(uint64_t count) const {
  if (count == 0) return absl::InvalidArgumentError("count must be >= 1");
  if (count > limits_.max_set_count) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "count %d is above the largest set this server samples, %d samples (max_set_count)",
        count, limits_.max_set_count));
  }
  return absl::OkStatus();
}

absl::StatusOr<PreparedTree> SamplingEngine::Prepare(const TreeSpec& spec, uint64_t count,
                                                     const BuildControl& caller) const {
  RETURN_IF_ERROR(CheckCount(count));
  for (const auto* text : {&spec.surface, &spec.density}) {
    if (text->size() > limits_.max_spec_length) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "a surface or density spec of %d characters is longer than the limit of %d "
          "(max_spec_length)",
          text->size(), limits_.max_spec_length));
    }
  }
  ASSIGN_OR_RETURN(const SpecKind found, KindOf(spec.surface));
  ASSIGN_OR_RETURN(
      ResolvedSurface resolved,
      found.kind->Resolve(spec, found.model ? &*found.model : nullptr, Context(caller)));
  PreparedTree prepared;
  prepared.key = std::move(resolved.key);
  prepared.grade = CurveTree::GradeFor(count);
  prepared.kind = found.kind->info().name;
  prepared.open_cursor = std::move(resolved.open_cursor);
  prepared.measure = std::move(resolved.measure);
  auto lookup = source_->Get(prepared.key, prepared.grade, resolved.factory, caller);
  if (!lookup.ok()) {
    // What was parsed for a tree that failed is not kept for a next request
    // (its memory goes once no request holds it); a request that left keeps it.
    const absl::StatusCode code = lookup.status().code();
    if (resolved.forget && code != absl::StatusCode::kCancelled &&
        code != absl::StatusCode::kDeadlineExceeded && code != absl::StatusCode::kUnavailable) {
      resolved.forget();
    }
    return lookup.status();
  }
  prepared.lookup = *std::move(lookup);
  return prepared;
}

absl::Status SamplingEngine::CheckRequest(const SampleRequest& request) const {
  RETURN_IF_ERROR(CheckCount(request.count));  // before anything is built for it
  if (request.count > MaxSequenceCount(request.sequence)) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "the %s sequence supports at most 2^32 samples", SequenceName(request.sequence)));
  }
  ASSIGN_OR_RETURN(const auto range, ResolveIndexRange(request));
  if (range.second - range.first > limits_.max_count) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "this request covers %d samples, above this server's limit of %d samples per request "
        "(max_count); ask for index ranges or shards of at most that many (count may stay %d)",
        range.second - range.first, limits_.max_count, request.count));
  }
  if (SequenceIsTwoDimensional(request.sequence) && request.count > limits_.max_sorted_range) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "the %s sequence sorts its whole set into curve order for every request (its index "
        "ranges and shards are positions in that order), so its count may be at most %d "
        "(max_sorted_range)",
        SequenceName(request.sequence), limits_.max_sorted_range));
  }
  if (!SequenceIsMonotone(request.sequence) &&
      range.second - range.first > limits_.max_sorted_range) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "the %s sequence is sorted into curve order per request, so a request may cover at most "
        "%d samples (max_sorted_range); ask for index ranges of that size",
        SequenceName(request.sequence), limits_.max_sorted_range));
  }
  if (request.sequence == SequenceKind::kBlue && request.count > limits_.max_blue_count) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "the blue sequence relaxes the whole set of %d samples in memory for every request (also "
        "for a shard, range or region of it), so it takes at most %d samples (max_blue_count)",
        request.count, limits_.max_blue_count));
  }
  RETURN_IF_ERROR(request.region.Validate());
  if (request.fields.face || request.fields.triangle) {
    ASSIGN_OR_RETURN(const std::optional<ModelSpec> model, ParseModelSpec(request.tree.surface));
    const SurfaceKind* kind = kinds_.For(model);
    if (request.fields.face)
      RETURN_IF_ERROR(CheckColumn(kinds_, kind, &KindInfo::face_column, "face"));
    if (request.fields.triangle) {
      RETURN_IF_ERROR(CheckColumn(kinds_, kind, &KindInfo::triangle_column, "triangle"));
    }
  }
  return absl::OkStatus();
}

absl::StatusOr<SamplingJob> SamplingEngine::Start(const SampleRequest& request,
                                                  const BuildControl& caller,
                                                  ColumnPrecision precision) const {
  RETURN_IF_ERROR(CheckRequest(request));
  const auto range = *ResolveIndexRange(request);  // CheckRequest resolved it
  ASSIGN_OR_RETURN(const uint64_t tree_count, ResolveTreeCount(request));
  SamplingJob job;
  ASSIGN_OR_RETURN(job.tree, Prepare(request.tree, tree_count, caller));
  const bool float32 = precision == ColumnPrecision::kFloat32;
  if (float32 && job.tree.measure) {
    RETURN_IF_ERROR(CheckFloat32Extent(job.tree.measure(), request.fields));
  }
  job.begin = range.first;
  job.end = range.second;
  CursorSpec cursor;
  cursor.begin = job.begin;
  cursor.end = job.end;
  cursor.region = request.region;
  cursor.fields = request.fields;
  cursor.threads = limits_.generation_threads;
  Sequence sequence(SequenceKind::kJittered, request.count, request.seed);
  if (request.sequence == SequenceKind::kBlue) {
    // The whole set, whatever part of it the request covers.
    ASSIGN_OR_RETURN(sequence, BlueSequence(job.tree.lookup, job.tree.open_cursor, request.count,
                                            request.seed, limits_.generation_threads, caller));
  } else {
    sequence = Sequence(request.sequence, request.count, request.seed);
  }
  ASSIGN_OR_RETURN(job.cursor, job.tree.open_cursor(job.tree.lookup, sequence, cursor));
  if (float32) job.cursor = Float32CheckedCursor(std::move(job.cursor), request.fields);
  return job;
}

}  // namespace sfc
