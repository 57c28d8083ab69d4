#include "client/cli/in_process_sample_source.h"

#include <algorithm>
#include <chrono>
#include <thread>

#include "absl/strings/str_format.h"
#include "base/status_macros.h"
#include "kinds/registered_kinds.h"
#include "request/stream_options.h"

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

// The report of an in-process tree, `seconds` after it was asked for.
TreeReport Report(const PreparedTree& tree, double seconds) {
  TreeReport report;
  report.tree = SummarizeTree(tree);
  report.seconds = seconds;
  return report;
}

}  // namespace

InProcessSampleSource::InProcessSampleSource(const SampleSourceOptions& options)
    : batch_size_(options.batch_size == 0 ? kDefaultBatchSize : options.batch_size),
      precision_(options.precision),
      engine_(RegisteredSurfaceKinds(), LimitsFor(options), &trees_, &files_) {}

absl::StatusOr<TreeReport> InProcessSampleSource::Prepare(const TreeSpec& spec, uint64_t count,
                                                          Progress* progress) {
  const auto start = std::chrono::steady_clock::now();
  progress->StartPhase("building the curve tree");
  auto prepared = engine_.Prepare(spec, count);
  progress->EndPhase();
  RETURN_IF_ERROR(prepared.status());
  return Report(*prepared, SecondsSince(start));
}

absl::StatusOr<std::string> InProcessSampleSource::Sample(const SampleRequest& request,
                                                          Progress* progress,
                                                          const TreeCallback& on_tree,
                                                          const BatchCallback& on_batch) {
  const auto start = std::chrono::steady_clock::now();
  progress->StartPhase("building the curve tree");
  auto job = engine_.Start(request, {}, precision_);
  progress->EndPhase();
  RETURN_IF_ERROR(job.status());
  if (on_tree) on_tree(Report(job->tree, SecondsSince(start)));
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

}  // namespace sfc
