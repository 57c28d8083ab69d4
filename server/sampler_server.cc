#include "server/sampler_server.h"

#include <algorithm>
#include <chrono>
#include <fstream>
#include <sstream>
#include <thread>

#include "absl/strings/str_format.h"
#include "grpcpp/ext/proto_server_reflection_plugin.h"
#include "grpcpp/health_check_service_interface.h"
#include "grpcpp/security/server_credentials.h"
#include "grpcpp/server_builder.h"
#include "spdlog/spdlog.h"

namespace sfc {
namespace {

absl::StatusOr<std::string> ReadFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) return absl::InvalidArgumentError(absl::StrFormat("cannot read \"%s\"", path));
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

absl::StatusOr<std::shared_ptr<grpc::ServerCredentials>> Credentials(const ServerOptions& o) {
  if (o.tls_cert_file.empty() && o.tls_key_file.empty()) return grpc::InsecureServerCredentials();
  if (o.tls_cert_file.empty() || o.tls_key_file.empty()) {
    return absl::InvalidArgumentError("TLS needs both --tls-cert and --tls-key");
  }
  auto cert = ReadFile(o.tls_cert_file);
  if (!cert.ok()) return cert.status();
  auto key = ReadFile(o.tls_key_file);
  if (!key.ok()) return key.status();
  grpc::SslServerCredentialsOptions ssl;
  ssl.pem_key_cert_pairs.push_back({*key, *cert});
  return grpc::SslServerCredentials(ssl);
}

// TCP connections in state ESTABLISHED whose local port is `port`, from
// /proc/net/tcp and tcp6 (0 where /proc is not readable).
int EstablishedConnections(int port) {
  int count = 0;
  for (const char* path : {"/proc/net/tcp", "/proc/net/tcp6"}) {
    std::ifstream in(path);
    std::string line;
    std::getline(in, line);  // header
    while (std::getline(in, line)) {
      std::istringstream fields(line);
      std::string slot, local, remote, state;
      fields >> slot >> local >> remote >> state;
      const size_t colon = local.rfind(':');
      if (colon == std::string::npos || state != "01") continue;  // 01 = ESTABLISHED
      if (std::stoi(local.substr(colon + 1), nullptr, 16) == port) ++count;
    }
  }
  return count;
}

}  // namespace

absl::StatusOr<std::unique_ptr<SamplerServer>> SamplerServer::Start(const ServerOptions& options) {
  auto server = std::unique_ptr<SamplerServer>(new SamplerServer());
  server->metrics_ = std::make_unique<ServerMetrics>();
  ServerMetrics* metrics = server->metrics_.get();
  server->cache_ = std::make_unique<TreeCache>(options.cache_bytes,
                                               [metrics](double s) { metrics->ObserveBuild(s); });
  server->service_ = std::make_unique<SamplerService>(options, server->cache_.get(), metrics);

  auto credentials = Credentials(options);
  if (!credentials.ok()) return credentials.status();

  grpc::EnableDefaultHealthCheckService(true);
  grpc::reflection::InitProtoReflectionServerBuilderPlugin();
  grpc::ServerBuilder builder;
  builder.AddListeningPort(options.address, *credentials, &server->port_);
  builder.RegisterService(server->service_.get());
  // Messages carry up to max_batch_size samples of up to 10 float64 columns.
  builder.SetMaxSendMessageSize(-1);
  server->server_ = builder.BuildAndStart();
  if (!server->server_ || server->port_ == 0) {
    return absl::UnavailableError(absl::StrFormat("cannot listen on %s", options.address));
  }
  server->server_->GetHealthCheckService()->SetServingStatus(true);

  if (!options.health_address.empty()) {
    grpc::ServerBuilder health;
    health.AddListeningPort(options.health_address, grpc::InsecureServerCredentials(),
                            &server->health_port_);
    server->health_server_ = health.BuildAndStart();
    if (!server->health_server_ || server->health_port_ == 0) {
      return absl::UnavailableError(absl::StrFormat("cannot listen on %s", options.health_address));
    }
    server->health_server_->GetHealthCheckService()->SetServingStatus(true);
  }
  if (!options.metrics_address.empty()) {
    try {
      server->exposer_ = std::make_unique<prometheus::Exposer>(options.metrics_address);
    } catch (const std::exception& e) {
      return absl::UnavailableError(
          absl::StrFormat("cannot serve metrics on %s: %s", options.metrics_address, e.what()));
    }
    server->cache_collector_ = metrics->CacheCollector(server->cache_.get());
    server->exposer_->RegisterCollectable(metrics->registry());
    server->exposer_->RegisterCollectable(server->cache_collector_);
  }
  spdlog::info("listening address={} port={} health_port={} metrics_port={} tls={} token={}",
               options.address, server->port_, server->health_port_, server->metrics_port(),
               !options.tls_cert_file.empty(), !options.token.empty());
  return server;
}

SamplerServer::~SamplerServer() {
  if (server_) Shutdown(0, 0);
}

int SamplerServer::metrics_port() const {
  if (!exposer_) return 0;
  const auto ports = exposer_->GetListeningPorts();
  return ports.empty() ? 0 : ports[0];
}

void SamplerServer::Shutdown(double grace_seconds, double drain_seconds) {
  if (!server_) return;
  server_->GetHealthCheckService()->SetServingStatus(false);
  if (health_server_) health_server_->GetHealthCheckService()->SetServingStatus(false);
  const auto deadline =
      std::chrono::system_clock::now() +
      std::chrono::milliseconds(static_cast<int64_t>(grace_seconds * 1000));
  server_->Shutdown(deadline);
  if (health_server_) health_server_->Shutdown(deadline);
  server_->Wait();
  if (health_server_) health_server_->Wait();
  // gRPC counts a call as done once its status is queued: a slow client may
  // still have a flow-control window or more of its last messages to read.
  // Keep the transports up until the clients have hung up (their TCP
  // connections to our port are gone), up to the grace deadline and at least
  // `drain_seconds` more.
  const auto drain_until = std::max(deadline, std::chrono::system_clock::now() +
                                                  std::chrono::milliseconds(static_cast<int64_t>(drain_seconds * 1000)));
  const auto calls_done = std::chrono::system_clock::now();
  const int open = EstablishedConnections(port_);
  while (drain_seconds > 0 && EstablishedConnections(port_) > 0 &&
         std::chrono::system_clock::now() < drain_until) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  spdlog::info("shutdown: calls done after {:.3f} s; {} client connections drained in {:.3f} s",
               std::chrono::duration<double>(calls_done - (deadline - std::chrono::milliseconds(
                                                                          static_cast<int64_t>(grace_seconds * 1000))))
                   .count(),
               open, std::chrono::duration<double>(std::chrono::system_clock::now() - calls_done).count());
  server_.reset();
  health_server_.reset();
}

}  // namespace sfc
