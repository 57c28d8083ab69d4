#include <chrono>
#include <cstdint>

#include "absl/strings/str_format.h"
#include "base/echo.h"
#include "base/status_macros.h"
#include "core/blue_relaxation.h"
#include "proto/convert.h"
#include "request/index_range.h"
#include "request/stream_options.h"
#include "request/tree_count.h"
#include "server/message_pipeline.h"
#include "server/request_control.h"
#include "server/sampler_service.h"
#include "spdlog/spdlog.h"

namespace sfc {

namespace v1 = ::sfcsampler::v1;
namespace {

// What a stream holds while it runs: the sort of a non-monotone sequence's
// range (16 bytes a sample; a sobol set sorts its whole count, 16 bytes a
// sample, core/curve_samples.h CurveAddress, and on a CAD model first lists
// each face's samples, 4 bytes a sample more), a blue set's relaxation (the
// whole set), the producer's batch (per sample the index and the columns in
// float64, the model columns uint32), and the messages of its
// pipeline, at most pipeline_depth + 2 (queued, being made, being written;
// MessagePipeline; one without a pipeline), each per sample the columns on
// the wire (float32 if asked; indices listed, at most). The batch is the requested size, or the
// largest the server would choose. An invalid range counts nothing here:
// SamplingEngine::CheckRequest has refused it before.
uint64_t StreamWorkingBytes(const SampleRequest& request, const StreamOptions& stream,
                            int pipeline_depth) {
  const auto range = ResolveIndexRange(request);
  const uint64_t n = range.ok() ? range->second - range->first : 0;
  // A blue set is relaxed whole, whatever part of it the stream sends.
  const uint64_t blue =
      request.sequence == SequenceKind::kBlue ? kBlueNoiseBytesPerSample * request.count : 0;
  const uint64_t sorted = SequenceIsTwoDimensional(request.sequence) ? request.count : n;
  const uint64_t sort_bytes = SequenceIsTwoDimensional(request.sequence) ? 20 : 16;
  const uint64_t sort = SequenceIsMonotone(request.sequence) ? 0 : sort_bytes * sorted;
  const SampleFields& f = request.fields;
  SampleFields made = f;  // the engine makes u v x y z whatever the wire carries
  made.uv = made.xyz = true;
  const uint64_t columns = WireValueColumns(made), wire_columns = WireValueColumns(f);
  const uint64_t index_columns = (f.face ? 1 : 0) + (f.triangle ? 1 : 0);
  const uint64_t width = stream.precision == ColumnPrecision::kFloat32 ? 4 : 8;
  // The messages the stream holds, plus the serialized copy gRPC keeps of the
  // one being written until the transport has sent it.
  const uint64_t messages =
      (pipeline_depth <= 0 ? 1 : static_cast<uint64_t>(pipeline_depth) + 2) + 1;
  const uint64_t per_sample = (8 + 8 * columns + 4 * index_columns) +
                              messages * (8 + width * wire_columns + 4 * index_columns);
  const uint64_t batch = stream.batch_size != 0 ? stream.batch_size : kDefaultBatchSize;
  return sort + blue + per_sample * std::min(n, batch);
}

// What a request whose working memory (StreamWorkingBytes) is over the
// budget can ask instead: a blue set is relaxed whole (128 bytes a sample,
// which fewer columns hardly change), and a sobol set sorted whole, whatever
// part of it the stream sends, so only a smaller set needs less.
const char* LessWorkingMemory(SequenceKind sequence) {
  if (sequence == SequenceKind::kBlue) {
    return "the blue sequence relaxes its whole set whatever range, shard or region is asked: "
           "ask for a set of fewer samples (count)";
  }
  if (SequenceIsTwoDimensional(sequence)) {
    return "this sequence sorts its whole set whatever range, shard or region is asked: ask for "
           "a set of fewer samples (count) or fewer columns";
  }
  return "ask for a smaller index range, a smaller batch_size or fewer columns";
}

// The bytes the stream header takes in the first message, at most, over what
// may differ between two asks of the same request: whether the tree was
// cached or refined, and the batch_size echoed. So the largest batch size it
// lets MaxSamplesPerMessage name is accepted when the client asks for it.
size_t HeaderBytesBound(const v1::StreamHeader& header) {
  v1::StreamHeader largest = header;
  largest.mutable_tree()->set_cache_hit(true);
  largest.mutable_tree()->set_refined(true);
  largest.mutable_request()->set_batch_size(UINT32_MAX);
  return largest.ByteSizeLong();
}

}  // namespace

grpc::Status SamplerService::Sample(grpc::ServerContext* context, const v1::SampleRequest* request,
                                    grpc::ServerWriter<v1::SampleResponse>* writer) {
  const auto start = Clock::now();
  uint64_t sent = 0;
  grpc::Status status = Admit(*context);
  // The request is read from the wire once, here. One that does not read is
  // refused in its slot, as any other bad request, or before it takes one
  // when it names a model (PrepareModelOutsideSlot).
  const absl::StatusOr<SampleCall> call = FromProto(*request);
  std::optional<EarlyLookup> early;
  if (status.ok()) status = PrepareModelOutsideSlot(context, *request, call, &early);
  if (status.ok()) {
    // Claim a stream slot; give it back on every path out.
    if (active_streams_.fetch_add(1) >= options_.max_concurrent_streams) {
      active_streams_.fetch_sub(1);
      status =
          grpc::Status(grpc::StatusCode::RESOURCE_EXHAUSTED,
                       absl::StrFormat("%d sample streams are already running, the server's limit "
                                       "(max_concurrent_streams); retry later",
                                       options_.max_concurrent_streams));
    } else {
      metrics_->StreamStarted();
      status = call.ok() ? RunSample(context, *request, *call, early, writer, &sent)
                         : ToGrpcStatus(call.status());
      metrics_->StreamEnded();
      active_streams_.fetch_sub(1);
    }
  }
  metrics_->CountRequest("Sample", status.error_code());
  spdlog::info(
      "rpc=Sample peer={} surface=\"{}\" count={} sent={} seconds={:.3f} code={} msg=\"{}\"",
      Echo(context->peer()), LogField(request->tree().surface(), kMaxNameEcho), request->count(),
      sent, SecondsSince(start), static_cast<int>(status.error_code()),
      LogField(status.error_message(), kMaxStatusMessageBytes));
  return status;
}

grpc::Status SamplerService::CheckStream(const SampleCall& call) const {
  const SampleRequest& request = call.request;
  const StreamOptions& stream = call.stream;
  if (stream.batch_size > options_.max_batch_size) {
    return grpc::Status(grpc::StatusCode::INVALID_ARGUMENT,
                        absl::StrFormat("batch_size %d is above the server's limit of %d "
                                        "(max_batch_size)",
                                        stream.batch_size, options_.max_batch_size));
  }
  if (absl::Status valid = engine_.CheckRequest(request); !valid.ok()) return ToGrpcStatus(valid);
  return ToGrpcStatus(stream_memory_.CheckFits(
      StreamWorkingBytes(request, stream, options_.stream_pipeline_depth), "this stream",
      LessWorkingMemory(request.sequence)));
}

grpc::Status SamplerService::PrepareModelOutsideSlot(grpc::ServerContext* context,
                                                     const v1::SampleRequest& wire,
                                                     const absl::StatusOr<SampleCall>& call,
                                                     std::optional<EarlyLookup>* early) {
  // The wire's surface: whether the request names a model comes before
  // whether the rest of it reads.
  auto model = ParseModelSpec(wire.tree().surface());
  if (!model.ok() || !model->has_value()) return grpc::Status::OK;  // reported in a slot
  if (!call.ok()) return ToGrpcStatus(call.status());
  const SampleRequest& request = call->request;
  const auto deadline =
      Clock::now() + std::chrono::duration_cast<Clock::duration>(
                         std::chrono::duration<double>(options_.request_deadline_seconds));
  // The request's and its stream's checks first: a bad one is refused before a
  // tree is made for it.
  if (grpc::Status valid = CheckStream(*call); !valid.ok()) return valid;
  auto tree_count = ResolveTreeCount(request);
  if (!tree_count.ok()) return ToGrpcStatus(tree_count.status());
  auto prepared =
      engine_.Prepare(request.tree, *tree_count,
                      RequestControl(context, deadline, options_.request_deadline_seconds));
  if (!prepared.ok()) return ToGrpcStatus(prepared.status());
  *early = EarlyLookup{prepared->lookup.cache_hit, prepared->lookup.refined};
  return grpc::Status::OK;
}

grpc::Status SamplerService::RunSample(grpc::ServerContext* context, const v1::SampleRequest& wire,
                                       const SampleCall& call,
                                       const std::optional<EarlyLookup>& early,
                                       grpc::ServerWriter<v1::SampleResponse>* writer,
                                       uint64_t* sent) {
  const auto start = Clock::now();
  const auto deadline =
      start + std::chrono::duration_cast<Clock::duration>(
                  std::chrono::duration<double>(options_.request_deadline_seconds));
  const SampleRequest& request = call.request;
  const StreamOptions& stream = call.stream;
  const BuildControl control = RequestControl(context, deadline, options_.request_deadline_seconds);
  // The request's and its stream's checks first (again, cheaply, for a model
  // checked before its tree), so that a request the engine refuses gets its
  // reason rather than a memory refusal; then the stream's working memory,
  // reserved before its cursor sorts anything.
  if (grpc::Status valid = CheckStream(call); !valid.ok()) return valid;
  auto memory =
      stream_memory_.Reserve(StreamWorkingBytes(request, stream, options_.stream_pipeline_depth),
                             "this stream", LessWorkingMemory(request.sequence), control.check);
  if (!memory.ok()) return ToGrpcStatus(memory.status());
  auto job = engine_.Start(request, control, stream.precision);
  if (!job.ok()) return ToGrpcStatus(job.status());

  v1::StreamHeader header;
  TreeSummary summary = SummarizeTree(job->tree);
  if (early) {  // the tree was found before the slot (evicted since, it was made again)
    summary.cache_hit = early->cache_hit && summary.cache_hit;
    summary.refined = early->refined || summary.refined;
  }
  ToProto(summary, header.mutable_tree());
  header.set_algorithm_version(options_.algorithm_version);
  header.set_seed(request.seed);
  *header.mutable_request() = wire;  // echoed as it came
  header.set_begin(job->begin);
  header.set_end(job->end);
  header.set_expected_samples(
      request.region.kind == Region::Kind::kAll ? static_cast<int64_t>(job->end - job->begin) : -1);

  // Every message, the first with its header too, fits max_message_bytes.
  const bool indices_listed =
      request.region.kind != Region::Kind::kAll || !SequenceIsMonotone(request.sequence);
  // One computation both refuses a batch_size and names the largest accepted.
  const size_t header_bytes = HeaderBytesBound(header);
  const uint32_t fits = MaxSamplesPerMessage(request.fields, stream.precision, indices_listed,
                                             header_bytes, options_.max_message_bytes);
  if (fits == 0) {
    return grpc::Status(
        grpc::StatusCode::INVALID_ARGUMENT,
        absl::StrFormat("the stream header alone is %d bytes, more than the server's "
                        "max_message_bytes of %d; use shorter specs",
                        header_bytes, options_.max_message_bytes));
  }
  if (stream.batch_size > fits) {
    return grpc::Status(
        grpc::StatusCode::INVALID_ARGUMENT,
        absl::StrFormat("batch_size %d with these columns makes messages larger than the server's "
                        "max_message_bytes of %d; ask for at most %d samples a batch (or 0 to let "
                        "the server choose)",
                        stream.batch_size, options_.max_message_bytes, fits));
  }
  const uint32_t batch_size =
      stream.batch_size == 0 ? std::min(kDefaultBatchSize, fits) : stream.batch_size;

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
      case StreamWatchdog::Reason::kReadTimeout:  // a Sample stream reads nothing
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
  const SampleFields fields = request.fields;
  MessagePipeline pipeline(
      options_.stream_pipeline_depth,
      [&batch, cursor, fields, stream, batch_size](v1::SampleBatch* out) -> absl::StatusOr<size_t> {
        batch.Clear();
        ASSIGN_OR_RETURN(const size_t n, cursor->Next(batch_size, &batch));
        ToProto(batch, fields, stream, out);
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

}  // namespace sfc
