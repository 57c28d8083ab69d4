// Helpers shared by the tests that run a real server on loopback: a server
// with no health or metrics ports, a client connected to it (or another one,
// with a deadline of its own), and a plain request.
#ifndef SFCSAMPLER_TESTS_SERVER_TEST_UTIL_H_
#define SFCSAMPLER_TESTS_SERVER_TEST_UTIL_H_

#include <memory>
#include <string>

#include "client/sampler_client.h"
#include "gtest/gtest.h"
#include "server/sampler_server.h"

namespace sfc::testing {

inline ServerOptions LoopbackOptions() {
  ServerOptions o;
  o.address = "127.0.0.1:0";
  o.health_address = "";
  o.metrics_address = "";
  return o;
}

struct Running {
  std::unique_ptr<SamplerServer> server;
  std::unique_ptr<SamplerClient> client;
};

// Starts a server and connects a client with `client`'s options to it.
inline Running StartServer(const ServerOptions& options, ClientOptions client = {}) {
  Running r;
  auto server = SamplerServer::Start(options);
  EXPECT_TRUE(server.ok()) << server.status();
  r.server = *std::move(server);
  client.target = "127.0.0.1:" + std::to_string(r.server->port());
  r.client = *SamplerClient::Connect(client);
  return r;
}

// A further client of `server` with `options`, whose calls give up after
// `deadline_seconds` (ClientOptions::deadline_seconds).
inline std::unique_ptr<SamplerClient> ConnectWithDeadline(const SamplerServer& server,
                                                          double deadline_seconds,
                                                          ClientOptions options = {}) {
  options.target = "127.0.0.1:" + std::to_string(server.port());
  options.deadline_seconds = deadline_seconds;
  return *SamplerClient::Connect(options);
}

inline SampleRequest Request(const std::string& surface, uint64_t count, uint64_t seed = 1) {
  SampleRequest r;
  r.tree.surface = surface;
  r.count = count;
  r.seed = seed;
  return r;
}

}  // namespace sfc::testing

#endif  // SFCSAMPLER_TESTS_SERVER_TEST_UTIL_H_
