#include "server/sampler_service.h"

#include <chrono>

#include "absl/strings/str_format.h"
#include "catalog/catalog.h"
#include "proto/convert.h"
#include "spdlog/spdlog.h"

namespace sfc {
namespace {

namespace v1 = ::sfcsampler::v1;
using Clock = std::chrono::steady_clock;

constexpr uint32_t kDefaultBatchSize = 65536;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

}  // namespace

SamplerService::SamplerService(const ServerOptions& options, TreeCache* cache, ServerMetrics* metrics)
    : options_(options), cache_(cache), metrics_(metrics), engine_(options.limits, cache) {}

grpc::Status SamplerService::CheckToken(const grpc::ServerContext& context) const {
  if (draining_.load()) {
    return grpc::Status(grpc::StatusCode::UNAVAILABLE,
                        "the server is shutting down; retry on another replica or later");
  }
  if (options_.token.empty()) return grpc::Status::OK;
  const auto& md = context.client_metadata();
  auto it = md.find("authorization");
  const std::string expected = "Bearer " + options_.token;
  if (it == md.end() || std::string(it->second.data(), it->second.size()) != expected) {
    return grpc::Status(grpc::StatusCode::UNAUTHENTICATED,
                        "this server needs the header \"authorization: Bearer <token>\" "
                        "(sfcsampler --token-file)");
  }
  return grpc::Status::OK;
}

grpc::Status SamplerService::Sample(grpc::ServerContext* context, const v1::SampleRequest* request,
                                    grpc::ServerWriter<v1::SampleResponse>* writer) {
  const auto start = Clock::now();
  uint64_t sent = 0;
  grpc::Status status = CheckToken(*context);
  if (status.ok()) {
    // Claim a stream slot; give it back on every path out.
    if (active_streams_.fetch_add(1) >= options_.max_concurrent_streams) {
      active_streams_.fetch_sub(1);
      status = grpc::Status(
          grpc::StatusCode::RESOURCE_EXHAUSTED,
          absl::StrFormat("%d sample streams are already running, the server's limit "
                          "(max_concurrent_streams); retry later",
                          options_.max_concurrent_streams));
    } else {
      metrics_->StreamStarted();
      status = RunSample(context, *request, writer, &sent);
      metrics_->StreamEnded();
      active_streams_.fetch_sub(1);
    }
  }
  metrics_->CountRequest("Sample", status.error_code());
  spdlog::info("rpc=Sample peer={} surface=\"{}\" count={} sent={} seconds={:.3f} code={} msg=\"{}\"",
               context->peer(), request->tree().surface(), request->count(), sent,
               SecondsSince(start), static_cast<int>(status.error_code()), status.error_message());
  return status;
}

grpc::Status SamplerService::RunSample(grpc::ServerContext* context, const v1::SampleRequest& request,
                                       grpc::ServerWriter<v1::SampleResponse>* writer,
                                       uint64_t* sent) {
  const auto start = Clock::now();
  const uint32_t batch_size = request.batch_size() == 0 ? kDefaultBatchSize : request.batch_size();
  if (batch_size > options_.max_batch_size) {
    return grpc::Status(grpc::StatusCode::INVALID_ARGUMENT,
                        absl::StrFormat("batch_size %d is above the server's limit of %d "
                                        "(max_batch_size)",
                                        batch_size, options_.max_batch_size));
  }
  auto parsed = FromProto(request);
  if (!parsed.ok()) return ToGrpcStatus(parsed.status());
  auto job = engine_.Start(*parsed);
  if (!job.ok()) return ToGrpcStatus(job.status());

  v1::SampleResponse response;
  v1::StreamHeader* header = response.mutable_header();
  ToProto(job->tree, header->mutable_tree());
  header->set_algorithm_version(kAlgorithmVersion);
  header->set_seed(parsed->seed);
  *header->mutable_request() = request;
  header->set_begin(job->begin);
  header->set_end(job->end);
  header->set_expected_samples(parsed->region.kind == Region::Kind::kAll
                                   ? static_cast<int64_t>(job->end - job->begin)
                                   : -1);

  SampleBatch batch;
  bool first = true;
  while (true) {
    if (context->IsCancelled()) {
      return grpc::Status(grpc::StatusCode::CANCELLED, "the client cancelled the stream");
    }
    if (SecondsSince(start) > options_.request_deadline_seconds) {
      return grpc::Status(
          grpc::StatusCode::DEADLINE_EXCEEDED,
          absl::StrFormat("the stream ran past the server's request deadline of %g s after "
                          "sending %d samples; resume after the last index received",
                          options_.request_deadline_seconds, *sent));
    }
    batch.Clear();
    auto n = job->cursor->Next(batch_size, &batch);
    if (!n.ok()) {
      const absl::Status s = n.status();
      return grpc::Status(static_cast<grpc::StatusCode>(s.code()),
                          absl::StrFormat("%s (after %d samples were sent)", s.message(), *sent));
    }
    if (*n == 0 && !first) break;
    response.mutable_batch()->Clear();
    ToProto(batch, parsed->fields, request.precision(), response.mutable_batch());
    if (!writer->Write(response)) {
      return grpc::Status(grpc::StatusCode::CANCELLED, "the client went away mid-stream");
    }
    *sent += *n;
    metrics_->AddSamples(*n);
    if (first) {
      response.clear_header();
      first = false;
    }
    if (*n == 0) break;
  }
  context->AddTrailingMetadata("x-samples-sent", std::to_string(*sent));
  return grpc::Status::OK;
}

grpc::Status SamplerService::Prepare(grpc::ServerContext* context, const v1::PrepareRequest* request,
                                     v1::PrepareResponse* response) {
  const auto start = Clock::now();
  grpc::Status status = CheckToken(*context);
  if (status.ok()) {
    auto spec = FromProto(request->tree());
    if (!spec.ok()) {
      status = ToGrpcStatus(spec.status());
    } else {
      auto prepared = engine_.Prepare(*spec, request->count());
      if (!prepared.ok()) {
        status = ToGrpcStatus(prepared.status());
      } else {
        ToProto(*prepared, response->mutable_tree());
        response->set_seconds(SecondsSince(start));
      }
    }
  }
  metrics_->CountRequest("Prepare", status.error_code());
  spdlog::info("rpc=Prepare peer={} surface=\"{}\" count={} hit={} seconds={:.3f} code={} msg=\"{}\"",
               context->peer(), request->tree().surface(), request->count(),
               response->tree().cache_hit(), SecondsSince(start),
               static_cast<int>(status.error_code()), status.error_message());
  return status;
}

grpc::Status SamplerService::ListCatalog(grpc::ServerContext* context, const v1::ListCatalogRequest*,
                                         v1::ListCatalogResponse* response) {
  grpc::Status status = CheckToken(*context);
  if (status.ok()) {
    for (const CatalogEntry& e : SurfaceCatalog()) ToProto(e, response->add_surfaces());
    for (const CatalogEntry& e : DensityCatalog()) ToProto(e, response->add_densities());
    response->set_algorithm_version(kAlgorithmVersion);
  }
  metrics_->CountRequest("ListCatalog", status.error_code());
  return status;
}

grpc::Status SamplerService::GetCacheStats(grpc::ServerContext* context,
                                           const v1::GetCacheStatsRequest*, v1::CacheStats* response) {
  grpc::Status status = CheckToken(*context);
  if (status.ok()) {
    const TreeCacheStats s = cache_->stats();
    response->set_hits(s.hits);
    response->set_misses(s.misses);
    response->set_builds(s.builds);
    response->set_refinements(s.refinements);
    response->set_evictions(s.evictions);
    response->set_entries(s.entries);
    response->set_bytes(s.bytes);
    response->set_budget_bytes(cache_->budget_bytes());
    response->set_build_seconds(s.build_seconds);
    response->set_waits(s.waits);
    response->set_max_count(options_.limits.max_count);
    response->set_max_tree_leaves(options_.limits.max_tree_leaves);
    response->set_max_spec_length(options_.limits.max_spec_length);
    response->set_max_concurrent_streams(options_.max_concurrent_streams);
    response->set_max_batch_size(options_.max_batch_size);
    response->set_request_deadline_seconds(options_.request_deadline_seconds);
    response->set_active_streams(active_streams_.load());
    response->set_max_sorted_range(options_.limits.max_sorted_range);
    response->set_generation_threads(options_.limits.generation_threads);
  }
  metrics_->CountRequest("GetCacheStats", status.error_code());
  return status;
}

}  // namespace sfc
