// Every limit and setting of the server, with its default. Each is a flag of
// sfcsampler-server and is reported by GetCacheStats.
#ifndef SFCSAMPLER_SERVER_SERVER_OPTIONS_H_
#define SFCSAMPLER_SERVER_SERVER_OPTIONS_H_

#include <cstdint>
#include <string>

#include "engine/sample_request.h"

namespace sfc {

struct ServerOptions {
  std::string address = "0.0.0.0:50051";  // where the sampler service listens
  // Health-only listener for probes, without TLS or token ("" = none). The
  // health service is also on `address`, where it needs no token either.
  std::string health_address = "127.0.0.1:50052";
  std::string metrics_address = "127.0.0.1:9464";  // Prometheus /metrics ("" = none)

  // max_count, max_tree_leaves, max_spec_length, generation_threads (2 here).
  EngineLimits limits = [] {
    EngineLimits l;
    l.generation_threads = 2;
    return l;
  }();
  uint64_t cache_bytes = uint64_t{1} << 30;    // tree cache budget, 1 GiB
  uint32_t max_concurrent_streams = 64;        // Sample streams at once; more are RESOURCE_EXHAUSTED
  uint32_t max_batch_size = 1 << 20;           // samples per message a client may ask for
  double request_deadline_seconds = 600;       // longest a Sample stream may run
  double shutdown_grace_seconds = 10;          // SIGTERM: in-flight streams get this long

  // Security: TLS when both files are set; a bearer token required on every
  // sampler RPC when set (health checks stay open).
  std::string tls_cert_file, tls_key_file;
  std::string token;
};

}  // namespace sfc

#endif  // SFCSAMPLER_SERVER_SERVER_OPTIONS_H_
