#include "client/sampler_client.h"

#include <chrono>
#include <fstream>
#include <memory>
#include <sstream>
#include <thread>

#include "absl/strings/str_format.h"
#include "grpc/grpc.h"
#include "grpc/health/v1/health.grpc.pb.h"
#include "grpcpp/client_context.h"
#include "grpcpp/create_channel.h"
#include "grpcpp/security/credentials.h"
#include "proto/convert.h"
#include "request/index_range.h"
#include "request/model_spec.h"
#include "request/routing_key.h"

namespace sfc {
namespace {

namespace v1 = ::sfcsampler::v1;

absl::StatusOr<std::string> ReadPem(const std::string& path, const char* what) {
  std::ifstream in(path);
  if (!in) return absl::InvalidArgumentError(absl::StrFormat("cannot read %s \"%s\"", what, path));
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// FAILED_PRECONDITION when a resumed stream's header says it comes from
// another tree, algorithm version or seed than the stream it continues.
absl::Status CheckResumedHeader(const v1::StreamHeader& first, const v1::StreamHeader& resumed,
                                uint64_t received) {
  auto differs = [&](const char* what, const std::string& a, const std::string& b) {
    return absl::FailedPreconditionError(absl::StrFormat(
        "the stream was resumed on a server whose %s is %s, but it began with %s: the samples "
        "would "
        "mix two different sets, so the %d received so far are the only valid ones; restart the "
        "whole request (or pin it to servers of one release)",
        what, b, a, received));
  };
  if (first.algorithm_version() != resumed.algorithm_version()) {
    return differs("algorithm version", first.algorithm_version(), resumed.algorithm_version());
  }
  if (first.tree().key_with_grade() != resumed.tree().key_with_grade()) {
    return differs("tree key", first.tree().key_with_grade(), resumed.tree().key_with_grade());
  }
  if (first.seed() != resumed.seed()) {
    return differs("seed", std::to_string(first.seed()), std::to_string(resumed.seed()));
  }
  return absl::OkStatus();
}

}  // namespace

SamplerClient::SamplerClient(const ClientOptions& options, std::shared_ptr<grpc::Channel> channel)
    : options_(options), channel_(std::move(channel)), stub_(v1::Sampler::NewStub(channel_)) {}

absl::StatusOr<std::unique_ptr<SamplerClient>> SamplerClient::Connect(
    const ClientOptions& options) {
  std::shared_ptr<grpc::ChannelCredentials> credentials;
  if (options.tls) {
    grpc::SslCredentialsOptions ssl;
    if (!options.tls_root_certs_file.empty()) {
      auto roots = ReadPem(options.tls_root_certs_file, "TLS roots");
      if (!roots.ok()) return roots.status();
      ssl.pem_root_certs = *roots;
    }
    if (options.tls_cert_file.empty() != options.tls_key_file.empty()) {
      return absl::InvalidArgumentError("a client certificate needs both --tls-cert and --tls-key");
    }
    if (!options.tls_cert_file.empty()) {
      auto cert = ReadPem(options.tls_cert_file, "the client certificate");
      if (!cert.ok()) return cert.status();
      auto key = ReadPem(options.tls_key_file, "the client key");
      if (!key.ok()) return key.status();
      ssl.pem_cert_chain = *cert;
      ssl.pem_private_key = *key;
    }
    credentials = grpc::SslCredentials(ssl);
  } else {
    credentials = grpc::InsecureChannelCredentials();
  }
  grpc::ChannelArguments args;
  args.SetMaxReceiveMessageSize(-1);
  // gRPC's reconnect backoff starts at 1 s and grows to 120 s; a resume after
  // a server restart would meet a channel still waiting it out (and failing
  // calls at once) long after the server is back. Retry the connection every
  // 100 ms at first and never less often than once a second.
  args.SetInt(GRPC_ARG_INITIAL_RECONNECT_BACKOFF_MS, 100);
  args.SetInt(GRPC_ARG_MAX_RECONNECT_BACKOFF_MS, 1000);
  auto channel = grpc::CreateCustomChannel(options.target, credentials, args);
  return std::unique_ptr<SamplerClient>(new SamplerClient(options, std::move(channel)));
}

void SamplerClient::Decorate(grpc::ClientContext* context, const std::string& surface_key) const {
  if (!options_.token.empty()) context->AddMetadata("authorization", "Bearer " + options_.token);
  context->AddMetadata("x-surface-key", surface_key);
  if (options_.deadline_seconds > 0) {
    context->set_deadline(
        std::chrono::system_clock::now() +
        std::chrono::milliseconds(static_cast<int64_t>(options_.deadline_seconds * 1000)));
  }
}

SampleRequest SamplerClient::Range(SampleRequest request, uint64_t begin, uint64_t end) {
  request.shard_index = request.shard_count = 0;
  request.begin = begin;
  request.end = end;
  return request;
}

SampleRequest SamplerClient::Shard(SampleRequest request, uint64_t i, uint64_t k) {
  request.begin = request.end = 0;
  request.shard_index = i;
  request.shard_count = k;
  return request;
}

absl::StatusOr<StreamSummary> SamplerClient::Sample(const SampleRequest& request,
                                                    const BatchCallback& on_batch) {
  return Sample(request, options_.stream, on_batch);
}

absl::StatusOr<StreamSummary> SamplerClient::Sample(const SampleRequest& asked,
                                                    const StreamOptions& stream,
                                                    const BatchCallback& on_batch) {
  // A model file travels once: the server gets its bytes if it lacks them,
  // and the request names them by hash. Its spec is parsed once, for the
  // upload and to know whether a resume may upload again.
  const auto asked_model = ParseModelSpec(asked.tree.surface);
  if (!asked_model.ok()) return asked_model.status();
  SampleRequest request = asked;
  auto surface = EnsureModel(asked.tree.surface, *asked_model);
  if (!surface.ok()) return surface.status();
  request.tree.surface = *std::move(surface);
  const std::string key = RoutingKey(request.tree);
  const bool from_file = asked_model->has_value() && (*asked_model)->sha256.empty();
  const bool monotone = SequenceIsMonotone(request.sequence);
  StreamSummary summary;
  v1::StreamHeader first_header;  // summary.header as it came, to check resumes against
  bool have_header = false;
  // What to ask for next: monotone sets resume at the index after the last
  // one received (indices grow along the stream); others are re-requested
  // whole and the samples already delivered are skipped.
  SampleRequest next = request;
  uint64_t skip = 0;
  uint64_t last_index = 0;
  double backoff = options_.resume_backoff_seconds;
  SampleBatch batch;
  for (int attempt = 0;; ++attempt) {
    const v1::SampleRequest wire = ToProto(next, stream);
    grpc::ClientContext context;
    Decorate(&context, key);
    auto reader = stub_->Sample(&context, wire);
    v1::SampleResponse response;
    uint64_t this_stream = 0;
    absl::Status callback_error;
    while (reader->Read(&response)) {
      summary.wire_bytes += response.ByteSizeLong();
      if (response.has_header() && !have_header) {
        first_header = response.header();
        summary.header = FromProto(first_header);
        have_header = true;
      } else if (response.has_header()) {
        // A resumed stream must continue the same set: same tree, same
        // algorithm, same seed (a rolling upgrade could mix two sets).
        if (absl::Status s = CheckResumedHeader(first_header, response.header(), summary.received);
            !s.ok()) {
          callback_error = s;
          break;
        }
      }
      batch.Clear();
      if (absl::Status s = AppendFromProto(response.batch(), request.fields, &batch); !s.ok()) {
        callback_error = s;
        break;
      }
      if (batch.size() > 0 && !have_header) {
        callback_error = absl::DataLossError("samples arrived before the stream's header");
        break;
      }
      this_stream += batch.size();
      if (skip > 0) {
        // Drop what an earlier attempt already delivered (non-monotone sets).
        const size_t drop = std::min<uint64_t>(skip, batch.size());
        skip -= drop;
        SampleBatch rest;
        rest.AppendFrom(batch, drop, batch.size());
        batch = std::move(rest);
      }
      if (batch.size() == 0) continue;
      // Read before the callback, which may take the columns.
      const uint64_t n = batch.size();
      const uint64_t last = batch.index.back();
      if (absl::Status s = on_batch(summary.header, batch); !s.ok()) {
        callback_error = s;
        break;
      }
      summary.received += n;
      last_index = last;
    }
    if (!callback_error.ok()) {
      context.TryCancel();
      reader->Finish();
      return callback_error;
    }
    const grpc::Status status = reader->Finish();
    if (status.ok()) {
      // Every stream the server answers OK begins with its header.
      if (!have_header) return absl::DataLossError("the stream ended without its header");
      // Nothing silently lost: the server says how many it sent.
      const auto& trailers = context.GetServerTrailingMetadata();
      auto it = trailers.find("x-samples-sent");
      if (it != trailers.end() &&
          std::to_string(this_stream) != std::string(it->second.data(), it->second.size())) {
        return absl::DataLossError(
            absl::StrFormat("the server sent %s samples but %d arrived",
                            std::string(it->second.data(), it->second.size()), this_stream));
      }
      if (summary.header.expected_samples >= 0 &&
          summary.received != static_cast<uint64_t>(summary.header.expected_samples)) {
        return absl::DataLossError(absl::StrFormat(
            "expected %d samples, received %d", summary.header.expected_samples, summary.received));
      }
      return summary;
    }
    // Resumable: the server is unreachable, or a proxy reset the stream when
    // its replica died (nginx answers with RST_STREAM INTERNAL_ERROR, which
    // gRPC reports as INTERNAL). Requests are pure functions of their fields,
    // so asking again is safe.
    const bool transport_reset = status.error_code() == grpc::StatusCode::INTERNAL &&
                                 status.error_message().find("RST_STREAM") != std::string::npos;
    // Behind a proxy, a resume after the model's replica died reaches the
    // next replica on the ring, which lacks the model: upload it there
    // again (when the request named a local file) and resume.
    const bool model_moved =
        status.error_code() == grpc::StatusCode::NOT_FOUND && summary.resumes > 0 && from_file;
    const bool resumable =
        status.error_code() == grpc::StatusCode::UNAVAILABLE || transport_reset || model_moved;
    if (!resumable || attempt >= options_.max_resumes) {
      absl::Status s = FromGrpcStatus(status);
      return absl::Status(
          s.code(),
          absl::StrFormat("%s (received %d samples%s)", s.message(), summary.received,
                          summary.received ? absl::StrFormat(", last index %d", last_index) : ""));
    }
    // Resume.
    ++summary.resumes;
    const auto pause = std::chrono::milliseconds(static_cast<int64_t>(backoff * 1000));
    std::this_thread::sleep_for(pause);
    // A server that is restarting: wait up to as long again for the channel
    // to connect, so this attempt is not spent on a refused connection.
    channel_->WaitForConnected(std::chrono::system_clock::now() + pause);
    backoff *= 2;
    if (model_moved) {
      auto again = EnsureModel(asked.tree.surface, *asked_model);
      if (!again.ok()) return again.status();
    }
    if (monotone && summary.received > 0) {
      const auto range = ResolveIndexRange(request);
      if (!range.ok()) return range.status();
      next = Range(request, last_index + 1, range->second);
    } else if (!monotone) {
      skip = summary.received;
    }
  }
}

absl::StatusOr<PreparedSummary> SamplerClient::Prepare(const TreeSpec& asked, uint64_t count) {
  TreeSpec spec = asked;
  auto surface = EnsureModel(asked.surface);
  if (!surface.ok()) return surface.status();
  spec.surface = *std::move(surface);
  v1::PrepareRequest request;
  *request.mutable_tree() = ToProto(spec);
  request.set_count(count);
  grpc::ClientContext context;
  Decorate(&context, RoutingKey(spec));
  v1::PrepareResponse response;
  const grpc::Status status = stub_->Prepare(&context, request, &response);
  if (!status.ok()) return FromGrpcStatus(status);
  return PreparedSummary{FromProto(response.tree()), response.seconds()};
}

absl::StatusOr<v1::ListCatalogResponse> SamplerClient::ListCatalog() {
  grpc::ClientContext context;
  Decorate(&context, "");
  v1::ListCatalogResponse response;
  const grpc::Status status = stub_->ListCatalog(&context, {}, &response);
  if (!status.ok()) return FromGrpcStatus(status);
  return response;
}

absl::StatusOr<v1::CacheStats> SamplerClient::GetCacheStats() {
  grpc::ClientContext context;
  Decorate(&context, "");
  v1::CacheStats response;
  const grpc::Status status = stub_->GetCacheStats(&context, {}, &response);
  if (!status.ok()) return FromGrpcStatus(status);
  return response;
}

absl::StatusOr<v1::ModelInfo> SamplerClient::UploadModel(const std::string& format,
                                                         const std::string& name,
                                                         const std::string& bytes) {
  constexpr size_t kChunk = size_t{1} << 20;  // well under every message limit
  grpc::ClientContext context;
  const std::optional<ModelFormat> known = ModelFormatFromName(format);
  Decorate(&context, known ? ModelRoutingKey(*known, Sha256Hex(bytes)) : "");
  v1::ModelInfo info;
  auto writer = stub_->UploadModel(&context, &info);
  v1::ModelChunk chunk;
  chunk.set_format(format);
  chunk.set_name(name);
  chunk.set_total_bytes(bytes.size());
  size_t offset = 0;
  do {
    const size_t n = std::min(kChunk, bytes.size() - offset);
    chunk.set_data(bytes.substr(offset, n));
    offset += n;
    // A failed write means the server ended the call early: Finish says why.
    if (!writer->Write(chunk)) break;
    chunk.clear_format();
    chunk.clear_name();
    chunk.clear_total_bytes();
  } while (offset < bytes.size());
  writer->WritesDone();
  const grpc::Status status = writer->Finish();
  if (!status.ok()) {
    const absl::Status s = FromGrpcStatus(status);
    const std::string message(s.message());
    return absl::Status(s.code(), message + UploadCutHint(message, bytes.size()));
  }
  return info;
}

absl::StatusOr<std::string> SamplerClient::EnsureModel(const std::string& spec) {
  auto parsed = ParseModelSpec(spec);
  if (!parsed.ok()) return parsed.status();
  return EnsureModel(spec, *parsed);
}

absl::StatusOr<std::string> SamplerClient::EnsureModel(const std::string& spec,
                                                       const std::optional<ModelSpec>& parsed) {
  if (!parsed.has_value()) return spec;
  if (!parsed->sha256.empty()) return FindOrUpload(parsed->format, parsed->sha256, nullptr);
  auto read = ReadModelFile(*parsed, kMaxModelFileBytes);
  if (!read.ok()) return read.status();
  return FindOrUpload(parsed->format, read->sha256, &*read);
}

absl::StatusOr<std::string> SamplerClient::EnsureModelBytes(ModelFormat format,
                                                            const std::string& name,
                                                            std::string bytes) {
  StoredModel local;
  local.format = format;
  local.sha256 = Sha256Hex(bytes);
  local.bytes = std::make_shared<const std::string>(std::move(bytes));
  local.name = name;
  return FindOrUpload(format, local.sha256, &local);
}

absl::StatusOr<std::string> SamplerClient::FindOrUpload(ModelFormat format,
                                                        const std::string& sha256,
                                                        const StoredModel* local) {
  v1::FindModelRequest find;
  find.set_sha256(sha256);
  find.set_format(std::string(ModelFormatName(format)));
  grpc::ClientContext context;
  Decorate(&context, ModelRoutingKey(format, sha256));
  v1::ModelInfo info;
  const grpc::Status found = stub_->FindModel(&context, find, &info);
  if (found.ok()) return info.spec();
  if (found.error_code() != grpc::StatusCode::NOT_FOUND || local == nullptr || !local->bytes) {
    return FromGrpcStatus(found);
  }
  auto uploaded = UploadModel(find.format(), local->name, *local->bytes);
  if (!uploaded.ok()) return uploaded.status();
  return uploaded->spec();
}

absl::StatusOr<bool> SamplerClient::CheckHealth(const std::string& service,
                                                double deadline_seconds) {
  auto stub = grpc::health::v1::Health::NewStub(channel_);
  grpc::ClientContext context;
  if (deadline_seconds <= 0) {
    deadline_seconds =
        options_.deadline_seconds > 0 ? options_.deadline_seconds : kHealthCheckSeconds;
  }
  context.set_deadline(std::chrono::system_clock::now() +
                       std::chrono::milliseconds(static_cast<int64_t>(deadline_seconds * 1000)));
  grpc::health::v1::HealthCheckRequest request;
  request.set_service(service);
  grpc::health::v1::HealthCheckResponse response;
  const grpc::Status status = stub->Check(&context, request, &response);
  if (!status.ok()) return FromGrpcStatus(status);
  return response.status() == grpc::health::v1::HealthCheckResponse::SERVING;
}

}  // namespace sfc
