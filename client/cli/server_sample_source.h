// ServerSampleSource: the SampleSource that asks an sfcsampler-server over
// gRPC (--server HOST:PORT) through a SamplerClient, made at the first call
// that needs it (reading the token and TLS files then). Its trees'
// summaries come from the wire's TreeInfo.
#ifndef SFCSAMPLER_CLIENT_CLI_SERVER_SAMPLE_SOURCE_H_
#define SFCSAMPLER_CLIENT_CLI_SERVER_SAMPLE_SOURCE_H_

#include <memory>
#include <mutex>

#include "client/cli/sample_source.h"
#include "client/sampler_client.h"

namespace sfc {

class ServerSampleSource final : public SampleSource {
 public:
  // REQUIRES: connection.server is not empty.
  ServerSampleSource(const ConnectionFlags& connection, const SampleSourceOptions& options);

  bool IsRemote() const override { return true; }
  absl::Status Connect() override;
  absl::StatusOr<TreeReport> Prepare(const TreeSpec& spec, uint64_t count,
                                     Progress* progress) override;
  absl::StatusOr<std::string> Sample(const SampleRequest& request, Progress* progress,
                                     const TreeCallback& on_tree,
                                     const BatchCallback& on_batch) override;
  absl::StatusOr<std::string> CacheStats() override;
  absl::StatusOr<bool> Serving() override;
  absl::StatusOr<std::string> UploadModel(const std::string& spec) override;
  absl::StatusOr<std::string> DescribeModel(const std::string& spec) override;
  absl::StatusOr<PreparedTree> LocalTree(const SampleRequest& request) override;

 private:
  // The client, connected on the first call; a failure is retried next time.
  absl::StatusOr<SamplerClient*> Client();

  const ConnectionFlags connection_;
  const SampleSourceOptions options_;
  std::mutex mu_;
  std::unique_ptr<SamplerClient> client_;  // GUARDED_BY(mu_)
};

}  // namespace sfc

#endif  // SFCSAMPLER_CLIENT_CLI_SERVER_SAMPLE_SOURCE_H_
