#include "server/sampler_service.h"

#include <chrono>

#include "base/echo.h"
#include "proto/convert.h"
#include "server/request_control.h"
#include "spdlog/spdlog.h"

namespace sfc {

namespace v1 = ::sfcsampler::v1;

grpc::Status SamplerService::Prepare(grpc::ServerContext* context,
                                     const v1::PrepareRequest* request,
                                     v1::PrepareResponse* response) {
  const auto start = Clock::now();
  grpc::Status status = Admit(*context);
  if (status.ok()) {
    auto spec = FromProto(request->tree());
    if (!spec.ok()) {
      status = ToGrpcStatus(spec.status());
    } else {
      const auto deadline =
          start + std::chrono::duration_cast<Clock::duration>(
                      std::chrono::duration<double>(options_.request_deadline_seconds));
      auto prepared =
          engine_.Prepare(*spec, request->count(),
                          RequestControl(context, deadline, options_.request_deadline_seconds));
      if (!prepared.ok()) {
        status = ToGrpcStatus(prepared.status());
      } else {
        ToProto(SummarizeTree(*prepared), response->mutable_tree());
        response->set_seconds(SecondsSince(start));
      }
    }
  }
  metrics_->CountRequest("Prepare", status.error_code());
  spdlog::info(
      "rpc=Prepare peer={} surface=\"{}\" count={} hit={} seconds={:.3f} code={} msg=\"{}\"",
      Echo(context->peer()), LogField(request->tree().surface(), kMaxNameEcho), request->count(),
      response->tree().cache_hit(), SecondsSince(start), static_cast<int>(status.error_code()),
      LogField(status.error_message(), kMaxStatusMessageBytes));
  return status;
}

}  // namespace sfc
