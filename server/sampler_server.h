// A running sfcsampler server: the sampler service with health checking and
// reflection on the main address, a health-only listener for probes, and the
// Prometheus endpoint. Used by sfcsampler-server and by the tests, which
// start real servers on loopback ports.
//
// Thread-safety: Shutdown() may be called from any thread, once.
#ifndef SFCSAMPLER_SERVER_SAMPLER_SERVER_H_
#define SFCSAMPLER_SERVER_SAMPLER_SERVER_H_

#include <memory>

#include "absl/status/statusor.h"
#include "grpcpp/server.h"
#include "prometheus/exposer.h"
#include "server/metrics.h"
#include "server/model_store.h"
#include "server/sampler_service.h"
#include "server/server_options.h"
#include "server/tree_cache.h"

namespace sfc {

class SamplerServer {
 public:
  // Starts listening. Port 0 in an address picks a free port (see port()).
  // Errors: INVALID_ARGUMENT for unreadable TLS files, UNAVAILABLE when an
  // address cannot be bound.
  static absl::StatusOr<std::unique_ptr<SamplerServer>> Start(const ServerOptions& options);
  ~SamplerServer();

  int port() const { return port_; }
  int health_port() const { return health_port_; }
  int metrics_port() const;

  // Graceful stop: health turns NOT_SERVING and new calls get UNAVAILABLE;
  // streams in flight run on for up to `grace_seconds` and then wait (at least
  // `drain_seconds`, up to the grace deadline) until their last bytes have left;
  // then the server closes, cancelling whatever still runs.
  void Shutdown(double grace_seconds, double drain_seconds = 1.0);

  const TreeCache& cache() const { return *cache_; }
  const ModelStore& models() const { return *models_; }
  const SamplerService& service() const { return *service_; }
  const ServerMetrics& metrics() const { return *metrics_; }

 private:
  SamplerServer() = default;

  std::unique_ptr<ServerMetrics> metrics_;
  std::unique_ptr<TreeCache> cache_;
  std::unique_ptr<ModelStore> models_;
  std::unique_ptr<SamplerService> service_;
  std::unique_ptr<grpc::Server> server_;
  std::unique_ptr<grpc::Server> health_server_;
  std::unique_ptr<prometheus::Exposer> exposer_;
  std::shared_ptr<prometheus::Collectable> cache_collector_;
  int port_ = 0;
  int health_port_ = 0;
};

}  // namespace sfc

#endif  // SFCSAMPLER_SERVER_SAMPLER_SERVER_H_
