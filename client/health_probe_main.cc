// sfcsampler-health-probe: asks a server's grpc.health.v1 service whether it
// is SERVING; exit 0 if so, 1 if not, 2 if it cannot tell. For container
// HEALTHCHECKs and Kubernetes probes (grpc_health_probe is not packaged in
// Debian).
//   sfcsampler-health-probe [--address 127.0.0.1:50052] [--timeout 2] [--service NAME]
#include <chrono>
#include <cstdio>
#include <string>

#include "CLI/CLI.hpp"
#include "grpc/health/v1/health.grpc.pb.h"
#include "grpcpp/client_context.h"
#include "grpcpp/create_channel.h"

int main(int argc, char** argv) {
  std::string address = "127.0.0.1:50052", service;
  double timeout = 2;
  CLI::App app{
      "sfcsampler-health-probe: exit 0 when the server is SERVING, 1 when not, 2 when it cannot "
      "tell"};
  app.add_option("--address", address, "host:port of the health listener")->capture_default_str();
  app.add_option("--timeout", timeout, "seconds to wait for the answer")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--service", service, "service name to check (\"\" = the whole server)");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // Usage errors are "cannot tell" (2), like an unreachable server.
    return app.exit(e) == 0 ? 0 : 2;
  }
  auto stub = grpc::health::v1::Health::NewStub(
      grpc::CreateChannel(address, grpc::InsecureChannelCredentials()));
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() +
                       std::chrono::milliseconds(static_cast<int64_t>(timeout * 1000)));
  grpc::health::v1::HealthCheckRequest request;
  request.set_service(service);
  grpc::health::v1::HealthCheckResponse response;
  const grpc::Status status = stub->Check(&context, request, &response);
  if (!status.ok()) {
    std::fprintf(stderr, "health check of %s failed: %s\n", address.c_str(),
                 status.error_message().c_str());
    return 2;
  }
  const bool serving = response.status() == grpc::health::v1::HealthCheckResponse::SERVING;
  std::printf("%s\n", serving ? "SERVING" : "NOT_SERVING");
  return serving ? 0 : 1;
}
