#include "server/metrics.h"

#include "prometheus/collectable.h"
#include "prometheus/metric_family.h"

namespace sfc {
namespace {

const char* CodeName(grpc::StatusCode code) {
  static const char* const kNames[] = {
      "OK", "CANCELLED", "UNKNOWN", "INVALID_ARGUMENT", "DEADLINE_EXCEEDED", "NOT_FOUND",
      "ALREADY_EXISTS", "PERMISSION_DENIED", "RESOURCE_EXHAUSTED", "FAILED_PRECONDITION",
      "ABORTED", "OUT_OF_RANGE", "UNIMPLEMENTED", "INTERNAL", "UNAVAILABLE", "DATA_LOSS",
      "UNAUTHENTICATED"};
  const int i = static_cast<int>(code);
  return i >= 0 && i <= 16 ? kNames[i] : "UNKNOWN";
}

// Reads the cache's counters when Prometheus scrapes.
class CacheStatsCollector final : public prometheus::Collectable {
 public:
  explicit CacheStatsCollector(const TreeCache* cache) : cache_(cache) {}
  std::vector<prometheus::MetricFamily> Collect() const override {
    const TreeCacheStats s = cache_->stats();
    std::vector<prometheus::MetricFamily> out;
    auto add = [&](const char* name, const char* help, prometheus::MetricType type, double value) {
      prometheus::MetricFamily f;
      f.name = name;
      f.help = help;
      f.type = type;
      prometheus::ClientMetric m;
      if (type == prometheus::MetricType::Counter) {
        m.counter.value = value;
      } else {
        m.gauge.value = value;
      }
      f.metric.push_back(m);
      out.push_back(std::move(f));
    };
    using T = prometheus::MetricType;
    add("sfcsampler_cache_hits_total", "Requests whose tree was cached", T::Counter, s.hits);
    add("sfcsampler_cache_misses_total", "Requests whose tree was not cached", T::Counter,
        s.misses);
    add("sfcsampler_cache_waits_total", "Requests that waited for another request's build",
        T::Counter, s.waits);
    add("sfcsampler_tree_builds_total", "Trees built from scratch", T::Counter, s.builds);
    add("sfcsampler_tree_refinements_total", "Trees made by refining a cached coarser tree",
        T::Counter, s.refinements);
    add("sfcsampler_cache_evictions_total", "Trees evicted for the memory budget", T::Counter,
        s.evictions);
    add("sfcsampler_cache_bytes", "Bytes of cached trees", T::Gauge, s.bytes);
    add("sfcsampler_cache_entries", "Cached trees", T::Gauge, s.entries);
    add("sfcsampler_cache_budget_bytes", "The cache's memory budget", T::Gauge,
        cache_->budget_bytes());
    add("sfcsampler_builds_running", "Tree builds running now", T::Gauge, s.builds_running);
    add("sfcsampler_building_bytes",
        "Bytes of trees being built (counted against the cache budget)", T::Gauge,
        s.building_bytes);
    add("sfcsampler_retired_tree_bytes",
        "Bytes of evicted trees that streams still hold (counted against the cache budget)",
        T::Gauge, s.retired_bytes);
    add("sfcsampler_tree_revivals_total",
        "Evicted trees a request took back into the cache while a stream still held them",
        T::Counter, s.revivals);
    add("sfcsampler_builds_queued", "Tree builds waiting for a builder thread", T::Gauge,
        s.builds_queued);
    add("sfcsampler_builds_stopped_total",
        "Tree builds stopped because every request left, or by shutdown", T::Counter,
        s.builds_stopped);
    add("sfcsampler_builds_failed_total", "Tree builds that ended with an error", T::Counter,
        s.builds_failed);
    add("sfcsampler_builds_rejected_total", "Misses turned away because the build queue was full",
        T::Counter, s.builds_rejected);
    add("sfcsampler_build_failure_hits_total", "Requests answered from a remembered failed build",
        T::Counter, s.failure_hits);
    return out;
  }

 private:
  const TreeCache* const cache_;
};

}  // namespace

ServerMetrics::ServerMetrics() : registry_(std::make_shared<prometheus::Registry>()) {
  requests_ = &prometheus::BuildCounter()
                   .Name("sfcsampler_requests_total")
                   .Help("RPCs handled, by method and status code")
                   .Register(*registry_);
  samples_ = &prometheus::BuildCounter()
                  .Name("sfcsampler_samples_streamed_total")
                  .Help("Samples written to clients")
                  .Register(*registry_)
                  .Add({});
  stalled_streams_ = &prometheus::BuildCounter()
                          .Name("sfcsampler_stalled_streams_total")
                          .Help("Streams cut because the client read nothing for the write timeout")
                          .Register(*registry_)
                          .Add({});
  active_streams_ = &prometheus::BuildGauge()
                         .Name("sfcsampler_active_streams")
                         .Help("Sample streams in progress")
                         .Register(*registry_)
                         .Add({});
  build_seconds_ = &prometheus::BuildHistogram()
                        .Name("sfcsampler_tree_build_seconds")
                        .Help("Time to build or refine a curve tree")
                        .Register(*registry_)
                        .Add({}, prometheus::Histogram::BucketBoundaries{
                                     0.001, 0.003, 0.01, 0.03, 0.1, 0.3, 1, 3, 10, 30});
}

std::shared_ptr<prometheus::Collectable> ServerMetrics::CacheCollector(
    const TreeCache* cache) const {
  return std::make_shared<CacheStatsCollector>(cache);
}

void ServerMetrics::CountRequest(const std::string& rpc, grpc::StatusCode code) {
  requests_->Add({{"rpc", rpc}, {"code", CodeName(code)}}).Increment();
}

}  // namespace sfc
