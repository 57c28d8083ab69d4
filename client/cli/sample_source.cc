#include "client/cli/sample_source.h"

#include "client/cli/in_process_sample_source.h"
#include "client/cli/server_sample_source.h"

namespace sfc {

std::unique_ptr<SampleSource> OpenSampleSource(const ConnectionFlags& connection,
                                               const SampleSourceOptions& options) {
  if (connection.server.empty()) return std::make_unique<InProcessSampleSource>(options);
  return std::make_unique<ServerSampleSource>(connection, options);
}

absl::StatusOr<SampleBatch> CollectSamples(SampleSource& source, const SampleRequest& request) {
  SampleBatch all;
  Progress silent(false);
  auto provenance = source.Sample(request, &silent, /*on_tree=*/nullptr,
                                  [&all](std::optional<uint64_t>, const SampleBatch& batch) {
                                    all.Append(batch);
                                    return absl::OkStatus();
                                  });
  if (!provenance.ok()) return provenance.status();
  return all;
}

}  // namespace sfc
