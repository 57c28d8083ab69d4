#include "server/sampler_service.h"

#include <chrono>

#include "absl/strings/str_format.h"
#include "base/echo.h"
#include "base/status_macros.h"
#include "catalog/catalog.h"
#include "kinds/registered_kinds.h"
#include "proto/convert.h"
#include "proto/service_convert.h"
#include "request/index_range.h"
#include "server/message_pipeline.h"
#include "spdlog/spdlog.h"

namespace sfc {
namespace {

namespace v1 = ::sfcsampler::v1;
using Clock = std::chrono::steady_clock;

constexpr uint32_t kDefaultBatchSize = 65536;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// A request's own check while its tree is built or waited for: the client
// is gone, or the server's request deadline has passed.
BuildControl RequestControl(const grpc::ServerContext* context, Clock::time_point deadline,
                            double deadline_seconds) {
  BuildControl control;
  control.check = [context, deadline, deadline_seconds]() -> absl::Status {
    if (context->IsCancelled()) {
      return absl::CancelledError("the client cancelled the request or its deadline passed");
    }
    if (Clock::now() > deadline) {
      return absl::DeadlineExceededError(absl::StrFormat(
          "the tree was still being built when the server's request deadline of %g s passed; "
          "retry later (the build goes on while other requests wait for it) or ask for fewer "
          "samples",
          deadline_seconds));
    }
    return absl::OkStatus();
  };
  return control;
}

// What a stream holds while it runs: the sort of a non-monotone sequence's
// range (16 bytes a sample), the producer's batch (per sample the index and
// the columns in float64, the model columns uint32), and the messages of its
// pipeline, at most pipeline_depth + 2 (queued, being made, being written;
// MessagePipeline; one without a pipeline), each per sample the columns on
// the wire (float32 if asked; indices listed, at most). The batch is the requested size, or the
// largest the server would choose. An invalid range counts nothing here:
// Start refuses it.
uint64_t StreamWorkingBytes(const SampleRequest& request, const v1::SampleRequest& wire,
                            int pipeline_depth) {
  const auto range = ResolveIndexRange(request);
  const uint64_t n = range.ok() ? range->second - range->first : 0;
  const uint64_t sort = Sequence(request.sequence, 1, 0).monotone() ? 0 : 16 * n;
  const SampleFields& f = request.fields;
  const uint64_t columns = 5 + (f.normal ? 3 : 0) + (f.density ? 1 : 0) + (f.curve_position ? 1 : 0);
  const uint64_t index_columns = (f.face ? 1 : 0) + (f.triangle ? 1 : 0);
  const uint64_t width = wire.precision() == v1::PRECISION_FLOAT32 ? 4 : 8;
  // The messages the stream holds, plus the serialized copy gRPC keeps of the
  // one being written until the transport has sent it.
  const uint64_t messages = (pipeline_depth <= 0 ? 1 : static_cast<uint64_t>(pipeline_depth) + 2) + 1;
  const uint64_t per_sample =
      (8 + 8 * columns + 4 * index_columns) + messages * (8 + width * columns + 4 * index_columns);
  const uint64_t batch = wire.batch_size() != 0 ? wire.batch_size() : kDefaultBatchSize;
  return sort + per_sample * std::min(n, batch);
}

}  // namespace

SamplerService::SamplerService(const ServerOptions& options, TreeCache* cache, ModelStore* models,
                               ServerMetrics* metrics, bool token_checked_by_transport)
    : options_(options),
      cache_(cache),
      models_(models),
      metrics_(metrics),
      engine_(RegisteredSurfaceKinds(),
          [&options] {
            EngineLimits limits = options.limits;
            limits.parse_failure_ttl_seconds = options.failure_ttl_seconds;
            return limits;
          }(),
          cache, models),
      authenticator_(options.token.empty() || token_checked_by_transport
                         ? nullptr
                         : std::make_unique<const TokenAuthenticator>(options.token)),
      watchdog_(options.write_timeout_seconds),
      stream_memory_(options.stream_memory_bytes) {
  // An evicted upload's parses go with it (their requests hold what they use).
  models_->SetEvictionListener(
      [this](const std::string& sha256) { engine_.loaded_models().ForgetModel(sha256); });
}

grpc::Status SamplerService::Admit(const grpc::ServerContext& context) const {
  if (draining_.load()) {
    return grpc::Status(grpc::StatusCode::UNAVAILABLE,
                        "the server is shutting down; retry on another replica or later");
  }
  if (!authenticator_) return grpc::Status::OK;
  const auto& md = context.client_metadata();
  auto it = md.find("authorization");
  if (it == md.end() || !authenticator_->Matches(std::string_view(it->second.data(), it->second.size()))) {
    return grpc::Status(grpc::StatusCode::UNAUTHENTICATED, TokenAuthenticator::kRefusal);
  }
  return grpc::Status::OK;
}

grpc::Status SamplerService::Sample(grpc::ServerContext* context, const v1::SampleRequest* request,
                                    grpc::ServerWriter<v1::SampleResponse>* writer) {
  const auto start = Clock::now();
  uint64_t sent = 0;
  grpc::Status status = Admit(*context);
  if (status.ok()) status = PrepareModelOutsideSlot(context, *request);
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
               Echo(context->peer()), Echo(request->tree().surface(), kMaxNameEcho),
               request->count(), sent, SecondsSince(start), static_cast<int>(status.error_code()),
               Echo(status.error_message(), kMaxStatusMessageBytes));
  return status;
}

grpc::Status SamplerService::PrepareModelOutsideSlot(grpc::ServerContext* context,
                                                     const v1::SampleRequest& request) {
  auto model = ParseModelSpec(request.tree().surface());
  if (!model.ok() || !model->has_value()) return grpc::Status::OK;  // RunSample says why
  auto parsed = FromProto(request);
  if (!parsed.ok()) return ToGrpcStatus(parsed.status());
  const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                           std::chrono::duration<double>(options_.request_deadline_seconds));
  auto prepared = engine_.Prepare(parsed->tree, parsed->tree_count ? parsed->tree_count : parsed->count,
                                  RequestControl(context, deadline, options_.request_deadline_seconds));
  if (!prepared.ok()) return ToGrpcStatus(prepared.status());
  return grpc::Status::OK;
}

grpc::Status SamplerService::RunSample(grpc::ServerContext* context, const v1::SampleRequest& request,
                                       grpc::ServerWriter<v1::SampleResponse>* writer,
                                       uint64_t* sent) {
  const auto start = Clock::now();
  const auto deadline = start + std::chrono::duration_cast<Clock::duration>(
                                    std::chrono::duration<double>(options_.request_deadline_seconds));
  auto parsed = FromProto(request);
  if (!parsed.ok()) return ToGrpcStatus(parsed.status());
  if (request.batch_size() > options_.max_batch_size) {
    return grpc::Status(grpc::StatusCode::INVALID_ARGUMENT,
                        absl::StrFormat("batch_size %d is above the server's limit of %d "
                                        "(max_batch_size)",
                                        request.batch_size(), options_.max_batch_size));
  }
  const BuildControl control = RequestControl(context, deadline, options_.request_deadline_seconds);
  // The stream's working memory, reserved before its cursor sorts anything.
  auto memory = stream_memory_.Reserve(
      StreamWorkingBytes(*parsed, request, options_.stream_pipeline_depth), "this stream",
      control.check);
  if (!memory.ok()) return ToGrpcStatus(memory.status());
  auto job = engine_.Start(*parsed, control);
  if (!job.ok()) return ToGrpcStatus(job.status());

  v1::StreamHeader header;
  ToProto(job->tree, header.mutable_tree());
  header.set_algorithm_version(options_.algorithm_version);
  header.set_seed(parsed->seed);
  *header.mutable_request() = request;
  header.set_begin(job->begin);
  header.set_end(job->end);
  header.set_expected_samples(parsed->region.kind == Region::Kind::kAll
                                   ? static_cast<int64_t>(job->end - job->begin)
                                   : -1);

  // Every message, the first with its header too, fits max_message_bytes.
  const bool indices_listed =
      parsed->region.kind != Region::Kind::kAll || !Sequence(parsed->sequence, 1, 0).monotone();
  const uint32_t fits = MaxSamplesPerMessage(parsed->fields, request.precision(), indices_listed,
                                             header.ByteSizeLong(), options_.max_message_bytes);
  if (fits == 0) {
    return grpc::Status(grpc::StatusCode::INVALID_ARGUMENT,
                        absl::StrFormat("the stream header alone is %d bytes, more than the server's "
                                        "max_message_bytes of %d; use shorter specs",
                                        header.ByteSizeLong(), options_.max_message_bytes));
  }
  if (request.batch_size() > fits) {
    return grpc::Status(
        grpc::StatusCode::INVALID_ARGUMENT,
        absl::StrFormat("batch_size %d with these columns makes messages larger than the server's "
                        "max_message_bytes of %d; ask for at most %d samples a batch (or 0 to let "
                        "the server choose)",
                        request.batch_size(), options_.max_message_bytes, fits));
  }
  const uint32_t batch_size =
      request.batch_size() == 0 ? std::min(kDefaultBatchSize, fits) : request.batch_size();

  const auto watch = watchdog_.Start(context);
  auto deadline_status = [&] {
    return grpc::Status(grpc::StatusCode::DEADLINE_EXCEEDED,
                        absl::StrFormat("the stream ran past the server's request deadline of %g s "
                                        "after sending %d samples; resume after the last index "
                                        "received",
                                        options_.request_deadline_seconds, *sent));
  };
  // Why the stream ended early: the watchdog's cut also shows as a cancelled
  // context.
  auto cut_status = [&](const char* otherwise) {
    switch (watch->reason()) {
      case StreamWatchdog::Reason::kWriteTimeout:
        metrics_->CountStalledStream();
        return grpc::Status(
            grpc::StatusCode::DEADLINE_EXCEEDED,
            absl::StrFormat("the client read nothing for %g s (the server's write_timeout), so the "
                            "stream was cut after %d samples; read faster or resume after the last "
                            "index received",
                            options_.write_timeout_seconds, *sent));
      case StreamWatchdog::Reason::kNone:
        break;
    }
    return grpc::Status(grpc::StatusCode::CANCELLED, otherwise);
  };

  // Generation runs on the pipeline's producer thread, one batch ahead of
  // (at most stream_pipeline_depth messages ahead of) the writes here. The
  // pipeline is declared last so that it stops before what it uses goes.
  SampleBatch batch;  // the producer's
  BatchCursor* const cursor = job->cursor.get();
  const SampleFields fields = parsed->fields;
  const v1::Precision precision = request.precision();
  const v1::ColumnEncoding encoding = request.column_encoding();
  MessagePipeline pipeline(options_.stream_pipeline_depth,
                           [&batch, cursor, fields, precision, encoding,
                            batch_size](v1::SampleBatch* out) -> absl::StatusOr<size_t> {
                             batch.Clear();
                             ASSIGN_OR_RETURN(const size_t n, cursor->Next(batch_size, &batch));
                             ToProto(batch, fields, precision, out, encoding);
                             return n;
                           });
  bool first = true;
  while (true) {
    if (context->IsCancelled()) return cut_status("the client cancelled the stream");
    if (Clock::now() > deadline) return deadline_status();
    // Wait in short steps, so that a cancel or the deadline is seen while a
    // batch is being generated.
    std::optional<MessagePipeline::Item> item = pipeline.Next(absl::Milliseconds(50));
    if (!item) continue;
    if (!item->response) {
      const absl::Status& s = item->status;
      if (s.ok()) break;
      return ToGrpcStatus(absl::Status(
          s.code(), absl::StrFormat("%s (after %d samples were sent)", s.message(), *sent)));
    }
    if (first) {
      *item->response->mutable_header() = std::move(header);
      first = false;
    }
    watch->BeginWrite();
    const bool written = writer->Write(*item->response);
    watch->EndWrite();
    if (!written) return cut_status("the client went away mid-stream");
    *sent += item->samples;
    metrics_->AddSamples(item->samples);
    pipeline.Recycle(std::move(item->response));
  }
  context->AddTrailingMetadata("x-samples-sent", std::to_string(*sent));
  return grpc::Status::OK;
}

grpc::Status SamplerService::Prepare(grpc::ServerContext* context, const v1::PrepareRequest* request,
                                     v1::PrepareResponse* response) {
  const auto start = Clock::now();
  grpc::Status status = Admit(*context);
  if (status.ok()) {
    auto spec = FromProto(request->tree());
    if (!spec.ok()) {
      status = ToGrpcStatus(spec.status());
    } else {
      const auto deadline = start + std::chrono::duration_cast<Clock::duration>(
                                        std::chrono::duration<double>(options_.request_deadline_seconds));
      auto prepared = engine_.Prepare(*spec, request->count(),
                                      RequestControl(context, deadline, options_.request_deadline_seconds));
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
               Echo(context->peer()), Echo(request->tree().surface(), kMaxNameEcho),
               request->count(), response->tree().cache_hit(), SecondsSince(start),
               static_cast<int>(status.error_code()),
               Echo(status.error_message(), kMaxStatusMessageBytes));
  return status;
}

grpc::Status SamplerService::ListCatalog(grpc::ServerContext* context, const v1::ListCatalogRequest*,
                                         v1::ListCatalogResponse* response) {
  grpc::Status status = Admit(*context);
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
  grpc::Status status = Admit(*context);
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
    response->set_max_message_bytes(options_.max_message_bytes);
    response->set_write_timeout_seconds(options_.write_timeout_seconds);
    response->set_stream_memory_bytes(stream_memory_.budget_bytes());
    response->set_stream_memory_reserved(stream_memory_.reserved_bytes());
    response->set_stream_memory_waits(stream_memory_.waits());
    response->set_stream_pipeline_depth(options_.stream_pipeline_depth);
    response->set_max_concurrent_builds(options_.max_concurrent_builds);
    response->set_max_queued_builds(options_.max_queued_builds);
    response->set_builds_running(s.builds_running);
    response->set_building_bytes(s.building_bytes);
    response->set_retired_tree_bytes(s.retired_bytes);
    response->set_retired_trees(s.retired_trees);
    response->set_tree_revivals(s.revivals);
    response->set_retired_tree_waits(s.retired_waits);
    response->set_builds_queued(s.builds_queued);
    response->set_builds_stopped(s.builds_stopped);
    response->set_builds_failed(s.builds_failed);
    response->set_builds_rejected(s.builds_rejected);
    response->set_failure_hits(s.failure_hits);
    response->set_failure_ttl_seconds(options_.failure_ttl_seconds);
    const ModelStoreStats m = models_->stats();
    response->set_models(m.models);
    response->set_model_bytes(m.bytes);
    response->set_model_budget_bytes(models_->budget_bytes());
    response->set_max_model_bytes(models_->max_model_bytes());
    response->set_model_uploads(m.uploads);
    response->set_model_evictions(m.evictions);
    const LoadedModelsStats p = engine_.loaded_models().stats();
    const LoadedModelsOptions& po = engine_.loaded_models().options();
    response->set_parsed_models(p.models);
    response->set_parsed_model_bytes(p.bytes);
    response->set_parsed_model_budget_bytes(po.budget_bytes);
    response->set_model_parse_threads(po.parse_threads);
    response->set_model_parse_seconds(po.parse_seconds);
    response->set_model_parses(p.parses);
    response->set_model_parse_failures(p.parse_failures);
    response->set_model_parses_stopped(p.parses_stopped);
    response->set_model_parses_running(p.parsing);
    response->set_model_parses_queued(p.queued);
    response->set_max_queued_parses(po.max_queued_parses);
  }
  metrics_->CountRequest("GetCacheStats", status.error_code());
  return status;
}

static void ToProto(const StoredModel& model, bool already, v1::ModelInfo* out) {
  out->set_sha256(model.sha256);
  out->set_format(std::string(ModelFormatName(model.format)));
  out->set_bytes(model.bytes->size());
  out->set_already_stored(already);
  out->set_spec(model.Spec());
}

grpc::Status SamplerService::UploadModel(grpc::ServerContext* context,
                                         grpc::ServerReader<v1::ModelChunk>* reader,
                                         v1::ModelInfo* response) {
  const auto start = Clock::now();
  grpc::Status status = Admit(*context);
  std::string name, bytes;
  std::optional<ModelFormat> format;
  if (status.ok()) {
    v1::ModelChunk chunk;
    bool first = true;
    while (status.ok() && reader->Read(&chunk)) {
      if (first) {
        // The name is the client's: escaped and clipped before any message
        // or log line shows it, and never stored (the model is shared).
        name = Echo(chunk.name(), kMaxNameEcho);
        format = ModelFormatFromName(chunk.format());
        if (!format) {
          status = grpc::Status(grpc::StatusCode::INVALID_ARGUMENT,
                                absl::StrFormat("unknown model format \"%s\"; use step, iges, nurbs, "
                                                "obj or ply",
                                                Echo(chunk.format())));
        }
        first = false;
      }
      if (bytes.size() + chunk.data().size() > models_->max_model_bytes()) {
        // Stop reading now: the rest would only be thrown away.
        models_->CountRejected();
        status = grpc::Status(
            grpc::StatusCode::RESOURCE_EXHAUSTED,
            absl::StrFormat("the model \"%s\" is larger than this server's max_model_bytes of %d; "
                            "simplify or split it, or ask the operator to raise the limit",
                            name, models_->max_model_bytes()));
      } else {
        bytes += chunk.data();
      }
    }
    if (status.ok() && first) {
      status = grpc::Status(grpc::StatusCode::INVALID_ARGUMENT, "the upload carried no model");
    }
  }
  if (status.ok()) {
    bool already = false;
    auto stored = models_->Put(*format, std::move(bytes), name, &already);
    if (stored.ok()) {
      ToProto(*stored, already, response);
    } else {
      status = ToGrpcStatus(stored.status());
    }
  }
  metrics_->CountRequest("UploadModel", status.error_code());
  spdlog::info("rpc=UploadModel peer={} name=\"{}\" bytes={} sha256={} already={} seconds={:.3f} code={} msg=\"{}\"",
               Echo(context->peer()), name, response->bytes(), response->sha256(),
               response->already_stored(), SecondsSince(start),
               static_cast<int>(status.error_code()),
               Echo(status.error_message(), kMaxStatusMessageBytes));
  return status;
}

grpc::Status SamplerService::FindModel(grpc::ServerContext* context, const v1::FindModelRequest* request,
                                       v1::ModelInfo* response) {
  grpc::Status status = Admit(*context);
  if (status.ok()) {
    const std::string format = request->format().empty() ? "step" : request->format();
    auto spec = ParseModelSpec(absl::StrFormat("%s:sha256=%s", format, request->sha256()));
    if (!spec.ok()) {
      status = ToGrpcStatus(spec.status());
    } else if (!spec->has_value()) {
      status = grpc::Status(grpc::StatusCode::INVALID_ARGUMENT,
                            absl::StrFormat("unknown model format \"%s\"", Echo(format)));
    } else {
      auto found = models_->Resolve(**spec);
      if (found.ok()) {
        ToProto(*found, true, response);
      } else {
        status = ToGrpcStatus(found.status());
      }
    }
  }
  metrics_->CountRequest("FindModel", status.error_code());
  return status;
}

}  // namespace sfc
