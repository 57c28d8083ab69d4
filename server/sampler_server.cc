#include "server/sampler_server.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <sstream>
#include <thread>

#include "absl/strings/str_format.h"
#include "grpcpp/ext/proto_server_reflection_plugin.h"
#include "grpcpp/health_check_service_interface.h"
#include "grpcpp/security/server_credentials.h"
#include "grpcpp/server_builder.h"
#include "server/token_auth.h"
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

// The main port's credentials: TLS (mutual with a client CA) when configured,
// with the token checked by an AuthMetadataProcessor; else plaintext.
absl::StatusOr<std::shared_ptr<grpc::ServerCredentials>> Credentials(const ServerOptions& o) {
  if (o.tls_cert_file.empty() && o.tls_key_file.empty()) {
    if (!o.tls_client_ca_file.empty()) {
      return absl::InvalidArgumentError(
          "--tls-client-ca needs TLS: give --tls-cert and --tls-key too");
    }
    return grpc::InsecureServerCredentials();
  }
  if (o.tls_cert_file.empty() || o.tls_key_file.empty()) {
    return absl::InvalidArgumentError("TLS needs both --tls-cert and --tls-key");
  }
  auto cert = ReadFile(o.tls_cert_file);
  if (!cert.ok()) return cert.status();
  auto key = ReadFile(o.tls_key_file);
  if (!key.ok()) return key.status();
  grpc::SslServerCredentialsOptions ssl;
  ssl.pem_key_cert_pairs.push_back({*key, *cert});
  if (!o.tls_client_ca_file.empty()) {
    auto ca = ReadFile(o.tls_client_ca_file);
    if (!ca.ok()) return ca.status();
    ssl.pem_root_certs = *ca;
    ssl.client_certificate_request = GRPC_SSL_REQUEST_AND_REQUIRE_CLIENT_CERTIFICATE_AND_VERIFY;
  }
  auto credentials = grpc::SslServerCredentials(ssl);
  if (!o.token.empty())
    credentials->SetAuthMetadataProcessor(std::make_shared<TokenAuthProcessor>(o.token));
  return credentials;
}

// A timeout must be finite and > 0: 0 or less would cut every stream at
// once, NaN or infinity never.
absl::Status ValidateTimeout(const char* flag, double seconds) {
  if (std::isfinite(seconds) && seconds > 0) return absl::OkStatus();
  return absl::InvalidArgumentError(
      absl::StrFormat("%s must be a finite number of seconds > 0, got %g", flag, seconds));
}

absl::Status Validate(const ServerOptions& o) {
  if (o.max_message_bytes < (64u << 10)) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "--max-message-bytes must be at least 65536 (a header and a batch must fit), got %d",
        o.max_message_bytes));
  }
  if (absl::Status s = ValidateTimeout("--write-timeout", o.write_timeout_seconds); !s.ok()) {
    return s;
  }
  if (absl::Status s = ValidateTimeout("--upload-idle-timeout", o.upload_idle_timeout_seconds);
      !s.ok()) {
    return s;
  }
  if (!(std::isfinite(o.upload_min_bytes_per_second) && o.upload_min_bytes_per_second > 0)) {
    return absl::InvalidArgumentError(
        absl::StrFormat("--upload-min-rate must be a finite number of bytes a second > 0, got %g",
                        o.upload_min_bytes_per_second));
  }
  if (o.max_concurrent_builds < 1 || o.max_queued_builds < 0 || !(o.failure_ttl_seconds >= 0)) {
    return absl::InvalidArgumentError(
        "--max-concurrent-builds must be >= 1, --max-queued-builds and --failure-ttl >= 0");
  }
  // A server parses on threads of its own, never on its RPC threads.
  if (o.limits.model_parse_threads < 1) {
    return absl::InvalidArgumentError("--model-parse-threads must be >= 1");
  }
  return absl::OkStatus();
}

// TCP connections to local port `port` that still have data in their send
// queue, from /proc/net/tcp and tcp6 (0 where /proc is not readable).
int ConnectionsWithUnsentData(int port) {
  int count = 0;
  for (const char* path : {"/proc/net/tcp", "/proc/net/tcp6"}) {
    std::ifstream in(path);
    std::string line;
    std::getline(in, line);  // header
    while (std::getline(in, line)) {
      std::istringstream fields(line);
      std::string slot, local, remote, state, queues;
      fields >> slot >> local >> remote >> state >> queues;  // queues: "tx:rx", hex
      const size_t colon = local.rfind(':');
      if (colon == std::string::npos || queues.empty()) continue;
      if (std::stoi(local.substr(colon + 1), nullptr, 16) != port) continue;
      if (std::stoul(queues.substr(0, queues.find(':')), nullptr, 16) > 0) ++count;
    }
  }
  return count;
}

}  // namespace

absl::StatusOr<std::unique_ptr<SamplerServer>> SamplerServer::Start(const ServerOptions& options) {
  if (absl::Status s = Validate(options); !s.ok()) return s;
  auto credentials = Credentials(options);
  if (!credentials.ok()) return credentials.status();
  const bool tls = !options.tls_cert_file.empty();

  auto server = std::unique_ptr<SamplerServer>(new SamplerServer());
  server->metrics_ = std::make_unique<ServerMetrics>();
  ServerMetrics* metrics = server->metrics_.get();
  TreeCacheOptions cache_options;
  cache_options.budget_bytes = options.cache_bytes;
  cache_options.max_concurrent_builds = options.max_concurrent_builds;
  cache_options.max_queued_builds = options.max_queued_builds;
  cache_options.failure_ttl_seconds = options.failure_ttl_seconds;
  server->cache_ = std::make_unique<TreeCache>(cache_options,
                                               [metrics](double s) { metrics->ObserveBuild(s); });
  server->models_ = std::make_unique<ModelStore>(options.model_bytes, options.max_model_bytes);
  server->service_ =
      std::make_unique<SamplerService>(options, server->cache_.get(), server->models_.get(),
                                       metrics, /*token_checked_by_transport=*/tls);

  grpc::EnableDefaultHealthCheckService(true);
  grpc::reflection::InitProtoReflectionServerBuilderPlugin();
  grpc::ServerBuilder builder;
  builder.AddListeningPort(options.address, *credentials, &server->port_);
  builder.RegisterService(server->service_.get());
  // Batches are sized to fit; this is the backstop. Uploads come in chunks
  // of 1 MiB, requests are small: the default 4 MiB receive limit holds.
  builder.SetMaxSendMessageSize(static_cast<int>(options.max_message_bytes));
  // Sync-server threads wake this often to notice shutdown (gRPC's default of
  // 10 s would hold up a graceful stop by that long).
  builder.SetSyncServerOption(grpc::ServerBuilder::SyncServerOption::CQ_TIMEOUT_MSEC, 200);
  server->server_ = builder.BuildAndStart();
  if (!server->server_ || server->port_ == 0) {
    return absl::UnavailableError(absl::StrFormat("cannot listen on %s", options.address));
  }
  server->server_->GetHealthCheckService()->SetServingStatus(true);

  if (!options.health_address.empty()) {
    grpc::ServerBuilder health;
    health.AddListeningPort(options.health_address, grpc::InsecureServerCredentials(),
                            &server->health_port_);
    health.SetSyncServerOption(grpc::ServerBuilder::SyncServerOption::CQ_TIMEOUT_MSEC, 200);
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
  spdlog::info(
      "listening address={} port={} health_port={} metrics_port={} tls={} mutual_tls={} token={}",
      options.address, server->port_, server->health_port_, server->metrics_port(), tls,
      !options.tls_client_ca_file.empty(), !options.token.empty());
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
  using Clock = std::chrono::system_clock;
  const auto start = Clock::now();
  const auto deadline =
      start + std::chrono::milliseconds(static_cast<int64_t>(grace_seconds * 1000));
  const auto seconds_since = [](Clock::time_point t) {
    return std::chrono::duration<double>(Clock::now() - t).count();
  };
  server_->GetHealthCheckService()->SetServingStatus(false);
  if (health_server_) health_server_->GetHealthCheckService()->SetServingStatus(false);

  // 1. Refuse new work, let the streams in flight run to their end.
  service_->StartDraining();
  while (service_->active_streams() > 0 && Clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  // Streams still waiting for a tree build end at once when the builds stop
  // (UNAVAILABLE, "shutting down"); give their status a moment to leave.
  cache_->Stop();
  const auto builds_stopped = Clock::now() + std::chrono::milliseconds(500);
  while (service_->active_streams() > 0 && Clock::now() < builds_stopped) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  const double streams_done = seconds_since(start);
  // 2. gRPC counts a call done once its status is queued, and its Shutdown
  // closes the transports, dropping what a slow reader has not taken yet. So
  // wait while bytes are still leaving: until no connection to our port has
  // had unsent data for 200 ms (or none is left), up to the grace deadline
  // and at least `drain_seconds` after the streams ended.
  const auto drain_until =
      std::max(deadline, Clock::now() +
                             std::chrono::milliseconds(static_cast<int64_t>(drain_seconds * 1000)));
  auto quiet_since = Clock::now();
  while (drain_seconds > 0 && Clock::now() < drain_until) {
    if (ConnectionsWithUnsentData(port_) > 0) quiet_since = Clock::now();
    if (Clock::now() - quiet_since >= std::chrono::milliseconds(200)) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  // 3. Close; anything still running past the deadline is cancelled.
  server_->Shutdown(std::max(deadline, Clock::now()));
  if (health_server_) health_server_->Shutdown(Clock::now());
  server_->Wait();
  if (health_server_) health_server_->Wait();
  spdlog::info(
      "shutdown: streams done after {:.3f} s, transports flushed and closed after {:.3f} s",
      streams_done, seconds_since(start));
  server_.reset();
  health_server_.reset();
}

}  // namespace sfc
