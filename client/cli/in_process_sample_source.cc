#include "client/cli/in_process_sample_source.h"

#include <algorithm>
#include <chrono>
#include <thread>

#include "absl/strings/str_format.h"
#include "base/status_macros.h"
#include "core/curve_tree.h"
#include "kinds/registered_kinds.h"

namespace sfc {
namespace {

EngineLimits LimitsFor(const SampleSourceOptions& options) {
  EngineLimits limits;
  limits.generation_threads =
      options.generation_threads > 0
          ? options.generation_threads
          : static_cast<int>(std::max(1u, std::min(4u, std::thread::hardware_concurrency())));
  limits.model_check_program = options.model_check_program;
  limits.model_parse_seconds = options.model_parse_seconds;
  return limits;
}

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

TreeSummary::Cell ToCell(const DepthCapHit& hit) {
  TreeSummary::Cell cell;
  cell.test = hit.test == DepthCapHit::Test::kGeometry ? "flatness"
              : hit.test == DepthCapHit::Test::kMass   ? "mass"
                                                       : "singular";
  cell.u0 = hit.u0, cell.v0 = hit.v0, cell.size = hit.size;
  cell.measured = hit.measured, cell.limit = hit.limit;
  return cell;
}

// The summary of an in-process tree, `seconds` after it was asked for.
TreeSummary SummarizeTree(const PreparedTree& t, double seconds) {
  TreeSummary s;
  s.kind = std::string(t.kind);
  s.key_with_grade = t.key.HexWithGrade(t.grade);
  s.grade = t.grade;
  s.cache_hit = t.lookup.cache_hit;
  s.refined = t.lookup.refined;
  s.seconds = seconds;
  if (!t.lookup.tree) {  // a mesh's or a model's trees: their size only
    s.leaves = t.lookup.any->leaves();
    s.bytes = t.lookup.any->bytes();
    return s;
  }
  const CurveTree& tree = *t.lookup.tree;
  const PrecisionReport& precision = tree.precision();
  s.leaves = tree.leaf_count();
  s.bytes = tree.bytes();
  s.min_depth = tree.min_depth();
  s.max_depth = tree.max_depth();
  s.tolerance = tree.options().tolerance;
  s.error_samples = precision.error_samples;
  s.unresolved_error_samples = precision.unresolved_error_samples;
  s.warped_leaves = precision.warped_leaves;
  s.singular_leaves = precision.singular_leaves;
  s.flatness_capped_leaves = precision.geometry_capped_leaves;
  s.mass_capped_leaves = precision.mass_capped_leaves;
  for (const DepthCapHit& hit : precision.singular) s.singular.push_back(ToCell(hit));
  for (const DepthCapHit& hit : precision.worst) s.warnings.push_back(ToCell(hit));
  return s;
}

}  // namespace

InProcessSampleSource::InProcessSampleSource(const SampleSourceOptions& options)
    : batch_size_(options.batch_size == 0 ? 65536 : options.batch_size),
      engine_(RegisteredSurfaceKinds(), LimitsFor(options), &trees_, &files_) {}

absl::StatusOr<TreeSummary> InProcessSampleSource::Prepare(const TreeSpec& spec, uint64_t count,
                                                           Progress* progress) {
  const auto start = std::chrono::steady_clock::now();
  progress->StartPhase("building the curve tree");
  auto prepared = engine_.Prepare(spec, count);
  progress->EndPhase();
  RETURN_IF_ERROR(prepared.status());
  return SummarizeTree(*prepared, SecondsSince(start));
}

absl::StatusOr<std::string> InProcessSampleSource::Sample(const SampleRequest& request,
                                                          Progress* progress,
                                                          const TreeCallback& on_tree,
                                                          const BatchCallback& on_batch) {
  const auto start = std::chrono::steady_clock::now();
  progress->StartPhase("building the curve tree");
  auto job = engine_.Start(request);
  progress->EndPhase();
  RETURN_IF_ERROR(job.status());
  if (on_tree) on_tree(SummarizeTree(job->tree, SecondsSince(start)));
  std::optional<uint64_t> expected;
  if (request.region.kind == Region::Kind::kAll) expected = job->end - job->begin;
  SampleBatch batch;
  uint64_t done = 0;
  while (true) {
    batch.Clear();
    ASSIGN_OR_RETURN(const size_t n, job->cursor->Next(batch_size_, &batch));
    if (n == 0) break;
    RETURN_IF_ERROR(on_batch(expected, batch));
    done += n;
    progress->Samples(done, expected.value_or(0));
  }
  progress->Done();
  return absl::StrFormat("(%s, seed %d)", kAlgorithmVersion, request.seed);
}

absl::StatusOr<std::string> InProcessSampleSource::CacheStats() {
  return absl::FailedPreconditionError("cache statistics need --server HOST:PORT");
}

absl::StatusOr<bool> InProcessSampleSource::Serving() {
  return absl::FailedPreconditionError("health needs --server HOST:PORT");
}

absl::StatusOr<std::string> InProcessSampleSource::UploadModel(const std::string&) {
  return absl::FailedPreconditionError("upload needs --server HOST:PORT");
}

absl::StatusOr<std::string> InProcessSampleSource::DescribeModel(const std::string& spec) {
  return engine_.DescribeModel(spec);
}

absl::StatusOr<PreparedTree> InProcessSampleSource::LocalTree(const SampleRequest& request) {
  ASSIGN_OR_RETURN(SamplingJob job, engine_.Start(request));
  return std::move(job.tree);
}

}  // namespace sfc
