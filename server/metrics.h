// Prometheus metrics of the server: requests by RPC and status code, samples
// streamed, active streams, tree build time, and the tree cache's counters
// (read from the cache at scrape time). Thread-safe.
#ifndef SFCSAMPLER_SERVER_METRICS_H_
#define SFCSAMPLER_SERVER_METRICS_H_

#include <memory>
#include <string>

#include "grpcpp/support/status.h"
#include "prometheus/counter.h"
#include "prometheus/family.h"
#include "prometheus/gauge.h"
#include "prometheus/histogram.h"
#include "prometheus/registry.h"
#include "server/tree_cache.h"

namespace sfc {

class ServerMetrics {
 public:
  ServerMetrics();

  // Everything to expose: the registry and the cache collector. The cache
  // must outlive the returned collectables' use.
  std::shared_ptr<prometheus::Registry> registry() const { return registry_; }
  std::shared_ptr<prometheus::Collectable> CacheCollector(const TreeCache* cache) const;

  void CountRequest(const std::string& rpc, grpc::StatusCode code);
  void AddSamples(uint64_t n) { samples_->Increment(static_cast<double>(n)); }
  void StreamStarted() { active_streams_->Increment(); }
  void StreamEnded() { active_streams_->Decrement(); }
  void ObserveBuild(double seconds) { build_seconds_->Observe(seconds); }
  // A stream cut because its reader took nothing for the write timeout.
  void CountStalledStream() { stalled_streams_->Increment(); }
  double samples_streamed() const { return samples_->Value(); }
  double stalled_streams() const { return stalled_streams_->Value(); }

 private:
  std::shared_ptr<prometheus::Registry> registry_;
  prometheus::Family<prometheus::Counter>* requests_;
  prometheus::Counter* samples_;
  prometheus::Counter* stalled_streams_;
  prometheus::Gauge* active_streams_;
  prometheus::Histogram* build_seconds_;
};

}  // namespace sfc

#endif  // SFCSAMPLER_SERVER_METRICS_H_
