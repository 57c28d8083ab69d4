// C++ client library for sfcsampler.v1.
//
// Sample() streams a request's batches in curve order to a callback. When the
// stream breaks with UNAVAILABLE (a server restart) or a proxy's stream reset
// (RST_STREAM, when the replica behind it died) it resumes from the first
// index not yet received, so the
// callback sees every sample exactly once; anything short of the full set is
// an error that says how many samples arrived. A resumed stream must come
// from the same tree key, algorithm version and seed as the first, or the
// call fails with FAILED_PRECONDITION (a rolling upgrade would otherwise mix
// two sets). Every call carries the
// x-surface-key header for consistent-hash proxies: the tree key, or for a
// model (FindModel, UploadModel, a Sample naming it) the model's
// ModelRoutingKey, so all of them reach the replica that stores it. A resume
// that meets NOT_FOUND because the model's replica died uploads the model
// again (when the request named a local file) and goes on.
//
// The API speaks the request library's types (a request, its stream options,
// a tree's summary); only ListCatalog, GetCacheStats and UploadModel hand
// back wire messages.
//
// Thread-safety: a SamplerClient may be used from several threads at once.
#ifndef SFCSAMPLER_CLIENT_SAMPLER_CLIENT_H_
#define SFCSAMPLER_CLIENT_SAMPLER_CLIENT_H_

#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "absl/status/statusor.h"
#include "core/types/sample_batch.h"
#include "grpcpp/channel.h"
#include "request/model_spec.h"
#include "request/sample_request.h"
#include "request/stream_info.h"
#include "request/stream_options.h"
#include "request/tree_summary.h"
#include "sfcsampler/v1/sampler.grpc.pb.h"

namespace sfc {

struct ClientOptions {
  std::string target = "127.0.0.1:50051";   // host:port
  std::string token;                        // bearer token; "" = none
  bool tls = false;                         // use TLS ...
  std::string tls_root_certs_file;          // ... trusting these roots ("" = system roots)
  std::string tls_cert_file, tls_key_file;  // client certificate and key for mutual TLS ("" = none)
  int max_resumes = 5;                      // resumes per Sample() call
  // First wait before a resume; doubles each time. After each wait the
  // client waits up to as long again for the connection to come back.
  double resume_backoff_seconds = 0.2;
  double deadline_seconds = 0;  // per RPC; 0 = none
  // How Sample()'s samples travel unless a call says otherwise. Raw columns
  // (one memcpy a column at each end) rather than the wire's default, packed
  // repeated fields: servers that predate raw columns send packed ones
  // whatever is asked, and the client reads both.
  StreamOptions stream = {ColumnPrecision::kFloat64, /*batch_size=*/0, ColumnEncoding::kRaw};
};

struct StreamSummary {
  StreamInfo header;  // from the first stream
  uint64_t received = 0;
  int resumes = 0;
  uint64_t wire_bytes = 0;  // serialised size of the messages received, resumes included
};

// What Prepare() gives: the tree's summary and the seconds the call took on
// the server, any wait for a build included.
struct PreparedSummary {
  TreeSummary tree;
  double seconds = 0;
};

class SamplerClient {
 public:
  static absl::StatusOr<std::unique_ptr<SamplerClient>> Connect(const ClientOptions& options);

  // Called with each batch that holds samples, in curve order. The callback
  // may take the batch's columns (std::move): the client refills the batch
  // from the next message.
  using BatchCallback = std::function<absl::Status(const StreamInfo&, SampleBatch&)>;
  // Streams `request`, its samples travelling as `stream` says (the first
  // form: as the options' `stream`); a callback error cancels the stream and
  // is returned. A surface naming a model file ("step:part.step") is uploaded
  // first if the server lacks it (EnsureModel) and named by its hash.
  absl::StatusOr<StreamSummary> Sample(const SampleRequest& request, const BatchCallback& on_batch);
  absl::StatusOr<StreamSummary> Sample(const SampleRequest& request, const StreamOptions& stream,
                                       const BatchCallback& on_batch);

  // Builds (or finds in the server's cache) the tree of `spec` for `count`
  // samples; a model file is uploaded first as for Sample().
  absl::StatusOr<PreparedSummary> Prepare(const TreeSpec& spec, uint64_t count);
  absl::StatusOr<::sfcsampler::v1::ListCatalogResponse> ListCatalog();
  absl::StatusOr<::sfcsampler::v1::CacheStats> GetCacheStats();

  // Makes the model `spec` names available on the server and returns its
  // wire spec "FORMAT:sha256=<hex>": a "FORMAT:FILE" spec's file is read
  // here, and uploaded only if the server does not hold its bytes already
  // (FindModel first); a "FORMAT:sha256=..." spec is checked with FindModel. A
  // spec that names no model (a catalogue surface) comes back unchanged.
  absl::StatusOr<std::string> EnsureModel(const std::string& spec);
  // The same for a model given as its file's bytes (`name` for messages):
  // uploaded only if the server does not hold them.
  absl::StatusOr<std::string> EnsureModelBytes(ModelFormat format, const std::string& name,
                                               std::string bytes);
  // Uploads `bytes` as a model of `format` ("step", "obj", ...).
  absl::StatusOr<::sfcsampler::v1::ModelInfo> UploadModel(const std::string& format,
                                                          const std::string& name,
                                                          const std::string& bytes);
  // grpc.health.v1 Check of `service` ("" = the whole server): true when
  // SERVING. It sends no token. `deadline_seconds` 0: the options' deadline,
  // or kHealthCheckSeconds without one.
  static constexpr double kHealthCheckSeconds = 5;
  absl::StatusOr<bool> CheckHealth(const std::string& service = "", double deadline_seconds = 0);

  // Range and shard helpers: the same request restricted to [begin, end) or
  // to shard i of k.
  static SampleRequest Range(SampleRequest request, uint64_t begin, uint64_t end);
  static SampleRequest Shard(SampleRequest request, uint64_t i, uint64_t k);

 private:
  explicit SamplerClient(const ClientOptions& options, std::shared_ptr<grpc::Channel> channel);
  // EnsureModel(spec) with `spec` already parsed: `parsed` is
  // ParseModelSpec(spec)'s value.
  absl::StatusOr<std::string> EnsureModel(const std::string& spec,
                                          const std::optional<ModelSpec>& parsed);
  // FindModel of `sha256`; when the server lacks it, UploadModel of `local`
  // (null: NOT_FOUND). Returns the server's spec of the model.
  absl::StatusOr<std::string> FindOrUpload(ModelFormat format, const std::string& sha256,
                                           const StoredModel* local);
  void Decorate(grpc::ClientContext* context, const std::string& surface_key) const;

  const ClientOptions options_;
  std::shared_ptr<grpc::Channel> channel_;
  std::unique_ptr<::sfcsampler::v1::Sampler::Stub> stub_;
};

}  // namespace sfc

#endif  // SFCSAMPLER_CLIENT_SAMPLER_CLIENT_H_
