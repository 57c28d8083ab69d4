// ServerSampleSource: the SampleSource that asks an sfcsampler-server over
// gRPC (--server HOST:PORT) through a SamplerClient (OpenSampleSource makes
// it from the connection flags). Its trees' summaries come from the wire's
// TreeInfo.
#ifndef SFCSAMPLER_CLIENT_CLI_SERVER_SAMPLE_SOURCE_H_
#define SFCSAMPLER_CLIENT_CLI_SERVER_SAMPLE_SOURCE_H_

#include <memory>
#include <string>

#include "client/cli/sample_source.h"
#include "client/sampler_client.h"

namespace sfc {

class ServerSampleSource final : public SampleSource {
 public:
  // `server`: HOST:PORT, for messages. REQUIRES: client is not null.
  ServerSampleSource(std::string server, std::unique_ptr<SamplerClient> client);

  absl::StatusOr<TreeReport> Prepare(const TreeSpec& spec, uint64_t count,
                                     Progress* progress) override;
  absl::StatusOr<std::string> Sample(const SampleRequest& request, Progress* progress,
                                     const TreeCallback& on_tree,
                                     const BatchCallback& on_batch) override;

 private:
  const std::string server_;
  const std::unique_ptr<SamplerClient> client_;
};

}  // namespace sfc

#endif  // SFCSAMPLER_CLIENT_CLI_SERVER_SAMPLE_SOURCE_H_
