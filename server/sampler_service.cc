#include "server/sampler_service.h"

#include "kinds/registered_kinds.h"

namespace sfc {

namespace v1 = ::sfcsampler::v1;

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
      upload_watchdog_(options.upload_idle_timeout_seconds),
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
  if (it == md.end() ||
      !authenticator_->Matches(std::string_view(it->second.data(), it->second.size()))) {
    return grpc::Status(grpc::StatusCode::UNAUTHENTICATED, TokenAuthenticator::kRefusal);
  }
  return grpc::Status::OK;
}

}  // namespace sfc
