#include "client/cli/sample_source.h"

#include "base/status_macros.h"
#include "client/cli/in_process_sample_source.h"
#include "client/cli/server_sample_source.h"

namespace sfc {

absl::StatusOr<std::unique_ptr<SampleSource>> OpenSampleSource(const ConnectionFlags& connection,
                                                               const SampleSourceOptions& options) {
  if (connection.server.empty()) return std::make_unique<InProcessSampleSource>(options);
  ClientOptions client;
  client.stream.precision = options.precision;
  client.stream.batch_size = static_cast<uint32_t>(options.batch_size);
  ASSIGN_OR_RETURN(std::unique_ptr<SamplerClient> connected, ConnectClient(connection, client));
  return std::make_unique<ServerSampleSource>(connection.server, std::move(connected));
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
