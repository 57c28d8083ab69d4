// InProcessSampleSource: the SampleSource that runs the sampler in this
// process (the CLI's default, no --server): a SamplingEngine over freshly
// built trees (no cache) and model specs that name local files. Its trees'
// summaries come straight from the engine's PreparedTree. What only the
// sampler in this process can do (a model's face table, the curve tree
// itself) a subcommand asks its engine().
#ifndef SFCSAMPLER_CLIENT_CLI_IN_PROCESS_SAMPLE_SOURCE_H_
#define SFCSAMPLER_CLIENT_CLI_IN_PROCESS_SAMPLE_SOURCE_H_

#include "client/cli/sample_source.h"
#include "engine/model_source.h"
#include "engine/sampling_engine.h"
#include "engine/tree_source.h"

namespace sfc {

class InProcessSampleSource final : public SampleSource {
 public:
  explicit InProcessSampleSource(const SampleSourceOptions& options);

  absl::StatusOr<TreeReport> Prepare(const TreeSpec& spec, uint64_t count,
                                     Progress* progress) override;
  absl::StatusOr<std::string> Sample(const SampleRequest& request, Progress* progress,
                                     const TreeCallback& on_tree,
                                     const BatchCallback& on_batch) override;

  // The engine the samples come from (e.g. DescribeModel, or Start for the
  // tree itself); it lives as long as this source.
  SamplingEngine& engine() { return engine_; }

 private:
  const size_t batch_size_;
  const OutputPrecision precision_;  // checked by the engine (engine/float32_range.h)
  DirectTreeSource trees_;
  FileModelSource files_;
  SamplingEngine engine_;
};

}  // namespace sfc

#endif  // SFCSAMPLER_CLIENT_CLI_IN_PROCESS_SAMPLE_SOURCE_H_
