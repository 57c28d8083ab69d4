// The sfcsampler.v1.Sampler service: a thin adapter that parses requests into
// engine types, calls the engine, and converts results and errors.
//
// Sample streams use the synchronous API: each Write blocks until HTTP/2 flow
// control accepts the message, so a slow reader holds at most one batch in
// the server, and a cancelled or disconnected client makes the next Write
// fail at once, which ends the stream and frees its cursor and tree.
//
// Thread-safety: thread-safe; gRPC calls it from many threads.
#ifndef SFCSAMPLER_SERVER_SAMPLER_SERVICE_H_
#define SFCSAMPLER_SERVER_SAMPLER_SERVICE_H_

#include <atomic>
#include <memory>

#include "engine/sampling_engine.h"
#include "server/metrics.h"
#include "server/server_options.h"
#include "server/tree_cache.h"
#include "sfcsampler/v1/sampler.grpc.pb.h"

namespace sfc {

class SamplerService final : public ::sfcsampler::v1::Sampler::Service {
 public:
  // `cache` and `metrics` are not owned and must outlive the service.
  SamplerService(const ServerOptions& options, TreeCache* cache, ServerMetrics* metrics);

  grpc::Status Sample(grpc::ServerContext* context, const ::sfcsampler::v1::SampleRequest* request,
                      grpc::ServerWriter<::sfcsampler::v1::SampleResponse>* writer) override;
  grpc::Status Prepare(grpc::ServerContext* context, const ::sfcsampler::v1::PrepareRequest* request,
                       ::sfcsampler::v1::PrepareResponse* response) override;
  grpc::Status ListCatalog(grpc::ServerContext* context,
                           const ::sfcsampler::v1::ListCatalogRequest* request,
                           ::sfcsampler::v1::ListCatalogResponse* response) override;
  grpc::Status GetCacheStats(grpc::ServerContext* context,
                             const ::sfcsampler::v1::GetCacheStatsRequest* request,
                             ::sfcsampler::v1::CacheStats* response) override;

  uint32_t active_streams() const { return active_streams_.load(); }
  // From now on new calls get UNAVAILABLE ("shutting down"); streams in flight go on.
  void StartDraining() { draining_.store(true); }

 private:
  grpc::Status CheckToken(const grpc::ServerContext& context) const;
  grpc::Status RunSample(grpc::ServerContext* context, const ::sfcsampler::v1::SampleRequest& request,
                         grpc::ServerWriter<::sfcsampler::v1::SampleResponse>* writer,
                         uint64_t* sent);

  // Constant after construction.
  const ServerOptions options_;
  TreeCache* const cache_;
  ServerMetrics* const metrics_;
  const SamplingEngine engine_;

  std::atomic<uint32_t> active_streams_{0};
  std::atomic<bool> draining_{false};
};

}  // namespace sfc

#endif  // SFCSAMPLER_SERVER_SAMPLER_SERVICE_H_
