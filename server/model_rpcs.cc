#include "server/sampler_service.h"

#include <algorithm>
#include <chrono>

#include "absl/strings/str_format.h"
#include "base/echo.h"
#include "proto/convert.h"
#include "proto/service_convert.h"
#include "server/request_control.h"
#include "spdlog/spdlog.h"

namespace sfc {

namespace v1 = ::sfcsampler::v1;

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
    // What Put would take: an upload past the store's whole budget is not
    // read to its end either.
    const uint64_t max_bytes = std::min(models_->max_model_bytes(), models_->budget_bytes());
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
      if (bytes.size() + chunk.data().size() > max_bytes) {
        // Stop reading now: the rest would only be thrown away.
        models_->CountRejected();
        status = grpc::Status(
            grpc::StatusCode::RESOURCE_EXHAUSTED,
            absl::StrFormat("the model \"%s\" is larger than this server takes (max_model_bytes %d, "
                            "model budget %d); simplify or split it, or ask the operator to raise "
                            "the limit",
                            name, models_->max_model_bytes(), models_->budget_bytes()));
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
