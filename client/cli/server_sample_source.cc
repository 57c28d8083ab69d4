#include "client/cli/server_sample_source.h"

#include <utility>

#include "absl/strings/str_format.h"
#include "base/status_macros.h"

namespace sfc {

ServerSampleSource::ServerSampleSource(std::string server, std::unique_ptr<SamplerClient> client)
    : server_(std::move(server)), client_(std::move(client)) {}

absl::StatusOr<TreeReport> ServerSampleSource::Prepare(const TreeSpec& spec, uint64_t count,
                                                       Progress* progress) {
  progress->StartPhase("waiting for " + server_ + " to prepare the curve tree");
  auto response = client_->Prepare(spec, count);
  progress->EndPhase();
  RETURN_IF_ERROR(response.status());
  TreeReport report;
  report.tree = std::move(response->tree);
  report.seconds = response->seconds;
  report.seconds_from_server = true;
  return report;
}

absl::StatusOr<std::string> ServerSampleSource::Sample(const SampleRequest& request,
                                                       Progress* progress,
                                                       const TreeCallback& on_tree,
                                                       const BatchCallback& on_batch) {
  uint64_t done = 0;
  progress->StartPhase("waiting for " + server_ + " (it may be building the curve tree)");
  ASSIGN_OR_RETURN(
      const StreamSummary summary,
      client_->Sample(request, [&](const StreamInfo& header, const SampleBatch& batch) {
        if (done == 0) {
          progress->EndPhase();
          if (on_tree) on_tree(TreeReport{header.tree});
        }
        std::optional<uint64_t> expected;
        if (header.expected_samples >= 0) expected = header.expected_samples;
        done += batch.size();
        progress->Samples(done, expected.value_or(0));
        return on_batch(expected, batch);
      }));
  progress->Done();
  return absl::StrFormat("from %s (%s, seed %d, %d resumes)", server_,
                         summary.header.algorithm_version, request.seed, summary.resumes);
}

}  // namespace sfc
