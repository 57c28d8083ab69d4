#include <algorithm>
#include <chrono>

#include "absl/strings/str_format.h"
#include "base/echo.h"
#include "proto/convert.h"
#include "proto/service/service_convert.h"
#include "server/request_control.h"
#include "server/sampler_service.h"
#include "spdlog/spdlog.h"

namespace sfc {

namespace v1 = ::sfcsampler::v1;

grpc::Status SamplerService::UploadModel(grpc::ServerContext* context,
                                         grpc::ServerReader<v1::ModelChunk>* reader,
                                         v1::ModelInfo* response) {
  const auto start = Clock::now();
  grpc::Status status = Admit(*context);
  std::string name, raw_name;  // escaped for messages; as sent, for the log's own escape
  std::optional<ModelFormat> format;
  // The bytes count against the model budget as they arrive (a declared size
  // at the first chunk).
  ModelStore::Upload upload = models_->StartUpload();
  // An uploader that stops sending is cut after upload_idle_timeout_seconds:
  // a blocked Read has no timeout of its own.
  const auto watch = upload_watchdog_.Start(context);
  const auto read = [&](v1::ModelChunk* chunk) {
    watch->BeginRead();
    const bool got = reader->Read(chunk);
    watch->EndRead();
    return got;
  };
  if (status.ok()) {
    v1::ModelChunk chunk;
    bool first = true;
    while (status.ok() && read(&chunk)) {
      if (first) {
        // The name is the client's: escaped and clipped before any message
        // or log line shows it, and never stored (the model is shared).
        raw_name = chunk.name();
        name = Echo(chunk.name(), kMaxNameEcho);
        format = ModelFormatFromName(chunk.format());
        if (!format) {
          status = grpc::Status(grpc::StatusCode::INVALID_ARGUMENT,
                                absl::StrFormat("unknown model format \"%s\"; use %s",
                                                Echo(chunk.format()), ModelFormatList()));
        }
        first = false;
        if (status.ok() && chunk.total_bytes() > 0) {
          if (absl::Status expected = upload.Expect(chunk.total_bytes()); !expected.ok()) {
            status = grpc::Status(static_cast<grpc::StatusCode>(expected.code()),
                                  absl::StrFormat("upload \"%s\": %s", name, expected.message()));
            break;
          }
        }
      }
      // Past a limit, stop reading now: the rest would only be thrown away.
      if (absl::Status appended = upload.Append(std::move(*chunk.mutable_data())); !appended.ok()) {
        status = grpc::Status(static_cast<grpc::StatusCode>(appended.code()),
                              absl::StrFormat("upload \"%s\": %s", name, appended.message()));
      } else if (const double seconds = SecondsSince(start);
                 options_.upload_min_bytes_per_second *
                     (seconds - options_.upload_idle_timeout_seconds) >
                 static_cast<double>(upload.size())) {
        status = grpc::Status(
            grpc::StatusCode::DEADLINE_EXCEEDED,
            absl::StrFormat("upload \"%s\": %d bytes in %.1f s is slower than the server's "
                            "upload_min_rate of %g bytes a second (counted after the first %g "
                            "s), so the upload was cut; send the model faster",
                            name, upload.size(), seconds, options_.upload_min_bytes_per_second,
                            options_.upload_idle_timeout_seconds));
      }
    }
    if (watch->reason() == StreamWatchdog::Reason::kReadTimeout) {
      // The client sees CANCELLED (the cut stream cannot carry a status); the
      // log says why.
      status = grpc::Status(
          grpc::StatusCode::DEADLINE_EXCEEDED,
          absl::StrFormat("upload \"%s\": the client sent nothing for %g s (the server's "
                          "upload_idle_timeout) after %d bytes, so the upload was cut; send the "
                          "model without pauses",
                          name, options_.upload_idle_timeout_seconds, upload.size()));
    } else if (status.ok() && context->IsCancelled()) {
      status = grpc::Status(grpc::StatusCode::CANCELLED, "the client cancelled the upload");
    } else if (status.ok() && first) {
      status = grpc::Status(grpc::StatusCode::INVALID_ARGUMENT, "the upload carried no model");
    }
  }
  if (status.ok()) {
    bool already = false;
    auto stored = models_->Put(*format, std::move(upload), name, &already);
    if (stored.ok()) {
      ToProto(*stored, already, response);
    } else {
      status = ToGrpcStatus(stored.status());
    }
  }
  metrics_->CountRequest("UploadModel", status.error_code());
  spdlog::info(
      "rpc=UploadModel peer={} name=\"{}\" bytes={} sha256={} already={} seconds={:.3f} code={} "
      "msg=\"{}\"",
      Echo(context->peer()), LogField(raw_name, kMaxNameEcho), response->bytes(),
      response->sha256(), response->already_stored(), SecondsSince(start),
      static_cast<int>(status.error_code()),
      LogField(status.error_message(), kMaxStatusMessageBytes));
  return status;
}

grpc::Status SamplerService::FindModel(grpc::ServerContext* context,
                                       const v1::FindModelRequest* request,
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
