#include "server/sampler_service.h"

namespace sfc {

namespace v1 = ::sfcsampler::v1;

grpc::Status SamplerService::GetCacheStats(grpc::ServerContext* context,
                                           const v1::GetCacheStatsRequest*,
                                           v1::CacheStats* response) {
  grpc::Status status = Admit(*context);
  if (status.ok()) {
    const TreeCacheStats s = cache_->stats();
    response->set_hits(s.hits);
    response->set_misses(s.misses);
    response->set_builds(s.builds);
    response->set_refinements(s.refinements);
    response->set_evictions(s.evictions);
    response->set_entries(s.entries);
    response->set_bytes(s.bytes);
    response->set_budget_bytes(cache_->budget_bytes());
    response->set_build_seconds(s.build_seconds);
    response->set_waits(s.waits);
    response->set_max_count(options_.limits.max_count);
    response->set_max_set_count(options_.limits.max_set_count);
    response->set_max_tree_leaves(options_.limits.max_tree_leaves);
    response->set_max_spec_length(options_.limits.max_spec_length);
    response->set_max_concurrent_streams(options_.max_concurrent_streams);
    response->set_max_batch_size(options_.max_batch_size);
    response->set_request_deadline_seconds(options_.request_deadline_seconds);
    response->set_active_streams(active_streams_.load());
    response->set_max_sorted_range(options_.limits.max_sorted_range);
    response->set_generation_threads(options_.limits.generation_threads);
    response->set_max_message_bytes(options_.max_message_bytes);
    response->set_write_timeout_seconds(options_.write_timeout_seconds);
    response->set_upload_idle_timeout_seconds(options_.upload_idle_timeout_seconds);
    response->set_upload_min_bytes_per_second(options_.upload_min_bytes_per_second);
    response->set_stream_memory_bytes(stream_memory_.budget_bytes());
    response->set_stream_memory_reserved(stream_memory_.reserved_bytes());
    response->set_stream_memory_waits(stream_memory_.waits());
    response->set_stream_pipeline_depth(options_.stream_pipeline_depth);
    response->set_max_concurrent_builds(options_.max_concurrent_builds);
    response->set_max_queued_builds(options_.max_queued_builds);
    response->set_builds_running(s.builds_running);
    response->set_building_bytes(s.building_bytes);
    response->set_retired_tree_bytes(s.retired_bytes);
    response->set_retired_trees(s.retired_trees);
    response->set_tree_revivals(s.revivals);
    response->set_retired_tree_waits(s.retired_waits);
    response->set_builds_queued(s.builds_queued);
    response->set_builds_stopped(s.builds_stopped);
    response->set_builds_failed(s.builds_failed);
    response->set_builds_rejected(s.builds_rejected);
    response->set_failure_hits(s.failure_hits);
    response->set_failure_ttl_seconds(options_.failure_ttl_seconds);
    const ModelStoreStats m = models_->stats();
    response->set_models(m.models);
    response->set_model_bytes(m.bytes);
    response->set_model_budget_bytes(models_->budget_bytes());
    response->set_max_model_bytes(models_->max_model_bytes());
    response->set_model_uploads(m.uploads);
    response->set_model_evictions(m.evictions);
    response->set_model_upload_bytes(m.upload_bytes);
    const LoadedModelsStats p = engine_.loaded_models().stats();
    const LoadedModelsOptions& po = engine_.loaded_models().options();
    response->set_parsed_models(p.models);
    response->set_parsed_model_bytes(p.bytes);
    response->set_parsed_model_budget_bytes(po.budget_bytes);
    response->set_model_parse_threads(po.parse_threads);
    response->set_model_parse_seconds(po.parse_seconds);
    response->set_model_parses(p.parses);
    response->set_model_parse_failures(p.parse_failures);
    response->set_model_parses_stopped(p.parses_stopped);
    response->set_model_parses_running(p.parsing);
    response->set_model_parses_queued(p.queued);
    response->set_max_queued_parses(po.max_queued_parses);
    response->set_parse_memory_bytes(po.working_budget_bytes);
    response->set_parse_memory_reserved(p.working_bytes);
    response->set_model_parse_fresh_seconds(po.fresh_seconds);
    response->set_max_long_parses(po.max_long_parses);
    response->set_max_parse_queue_seconds(po.max_queue_wait_seconds);
    response->set_model_parse_seconds_per_mib(options_.limits.model_parse_seconds_per_mib);
    response->set_model_parses_long(p.long_parses);
    response->set_model_parses_busy(p.parses_busy);
  }
  metrics_->CountRequest("GetCacheStats", status.error_code());
  return status;
}

}  // namespace sfc
