// The sfcsampler.v1.Sampler service: a thin adapter that parses requests into
// engine types, calls the engine, and converts results and errors (the
// conversions are proto/'s). One file per RPC: sample_rpc.cc, prepare_rpc.cc,
// catalog_rpc.cc, cache_stats_rpc.cc (the server's statistics, mapped here:
// they are the server's own types) and model_rpcs.cc (UploadModel, FindModel);
// this file has the constructor and the admission check.
//
// Sample streams use the synchronous API with generation pipelined: a
// producer thread per stream generates and encodes its messages while the
// RPC thread writes them (MessagePipeline, at most stream_pipeline_depth
// ready). Each Write blocks until HTTP/2 flow control accepts the message,
// so a slow reader holds at most depth + 2 messages in the server, and a
// cancelled or disconnected client makes the next Write fail at once, which
// ends the stream and frees its cursor and tree. A reader
// that stops reading is cut after the write timeout (StreamWatchdog), and an
// upload that stops sending after the upload idle timeout. Every
// message stays within max_message_bytes: the batch size follows from the
// requested columns.
//
// Thread-safety: thread-safe; gRPC calls it from many threads.
#ifndef SFCSAMPLER_SERVER_SAMPLER_SERVICE_H_
#define SFCSAMPLER_SERVER_SAMPLER_SERVICE_H_

#include <atomic>
#include <memory>
#include <optional>

#include "absl/status/statusor.h"
#include "engine/sampling_engine.h"
#include "request/stream_options.h"
#include "server/metrics.h"
#include "server/model_store.h"
#include "server/server_options.h"
#include "server/stream_memory.h"
#include "server/stream_watchdog.h"
#include "server/token_auth.h"
#include "server/tree_cache.h"
#include "sfcsampler/v1/sampler.grpc.pb.h"

namespace sfc {

class SamplerService final : public ::sfcsampler::v1::Sampler::Service {
 public:
  // `cache`, `models` and `metrics` are not owned and must outlive the service.
  // `token_checked_by_transport`: an AuthMetadataProcessor already checks the
  // token (TLS ports), so the service does not.
  SamplerService(const ServerOptions& options, TreeCache* cache, ModelStore* models,
                 ServerMetrics* metrics, bool token_checked_by_transport);

  grpc::Status Sample(grpc::ServerContext* context, const ::sfcsampler::v1::SampleRequest* request,
                      grpc::ServerWriter<::sfcsampler::v1::SampleResponse>* writer) override;
  grpc::Status Prepare(grpc::ServerContext* context,
                       const ::sfcsampler::v1::PrepareRequest* request,
                       ::sfcsampler::v1::PrepareResponse* response) override;
  grpc::Status ListCatalog(grpc::ServerContext* context,
                           const ::sfcsampler::v1::ListCatalogRequest* request,
                           ::sfcsampler::v1::ListCatalogResponse* response) override;
  grpc::Status GetCacheStats(grpc::ServerContext* context,
                             const ::sfcsampler::v1::GetCacheStatsRequest* request,
                             ::sfcsampler::v1::CacheStats* response) override;
  grpc::Status UploadModel(grpc::ServerContext* context,
                           grpc::ServerReader<::sfcsampler::v1::ModelChunk>* reader,
                           ::sfcsampler::v1::ModelInfo* response) override;
  grpc::Status FindModel(grpc::ServerContext* context,
                         const ::sfcsampler::v1::FindModelRequest* request,
                         ::sfcsampler::v1::ModelInfo* response) override;

  uint32_t active_streams() const { return active_streams_.load(); }
  // From now on new calls get UNAVAILABLE ("shutting down"); streams in flight go on.
  void StartDraining() { draining_.store(true); }

 private:
  // UNAVAILABLE while draining; UNAUTHENTICATED without the token.
  grpc::Status Admit(const grpc::ServerContext& context) const;
  // The checks of a Sample that need no tree: its batch_size, the engine's
  // (SamplingEngine::CheckRequest) and whether its working memory could fit
  // the stream memory at all. Made before any tree is built for it.
  grpc::Status CheckStream(const SampleCall& call) const;
  // A Sample naming a model: its parse and tree, made (or waited for) before
  // the stream takes a slot, so a slow or hostile parse holds none; `call`
  // is `wire` as read (proto/convert.h FromProto), its error returned here
  // for a model. OK for other requests (their errors are reported in a slot).
  // `*early` gets how the tree was found then (a request that builds or
  // refines it here finds it cached in its slot).
  struct EarlyLookup {
    bool cache_hit = false, refined = false;
  };
  grpc::Status PrepareModelOutsideSlot(grpc::ServerContext* context,
                                       const ::sfcsampler::v1::SampleRequest& wire,
                                       const absl::StatusOr<SampleCall>& call,
                                       std::optional<EarlyLookup>* early);
  // Streams `call`, which `wire` reads as (the header echoes `wire`); its
  // stream options are passed down unchanged to the batch sizing and encoding.
  // The header's cache_hit and refined take in the lookup before the slot,
  // `early`, when there was one.
  grpc::Status RunSample(grpc::ServerContext* context, const ::sfcsampler::v1::SampleRequest& wire,
                         const SampleCall& call, const std::optional<EarlyLookup>& early,
                         grpc::ServerWriter<::sfcsampler::v1::SampleResponse>* writer,
                         uint64_t* sent);

  // Constant after construction.
  const ServerOptions options_;
  TreeCache* const cache_;
  ModelStore* const models_;
  ServerMetrics* const metrics_;
  const SamplingEngine engine_;
  // Set when the service itself checks the token (plaintext ports).
  const std::unique_ptr<const TokenAuthenticator> authenticator_;
  StreamWatchdog watchdog_;         // Sample streams' writes
  StreamWatchdog upload_watchdog_;  // UploadModel streams' reads
  StreamMemory stream_memory_;

  std::atomic<uint32_t> active_streams_{0};
  std::atomic<bool> draining_{false};
};

}  // namespace sfc

#endif  // SFCSAMPLER_SERVER_SAMPLER_SERVICE_H_
