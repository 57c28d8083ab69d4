// InProcessSampleSource: the SampleSource that runs the sampler in this
// process (the CLI's default, no --server): a SamplingEngine over freshly
// built trees (no cache) and model specs that name local files. Its trees'
// summaries come straight from the engine's PreparedTree.
#ifndef SFCSAMPLER_CLIENT_CLI_IN_PROCESS_SAMPLE_SOURCE_H_
#define SFCSAMPLER_CLIENT_CLI_IN_PROCESS_SAMPLE_SOURCE_H_

#include "client/cli/sample_source.h"
#include "engine/model_source.h"
#include "engine/tree_source.h"

namespace sfc {

class InProcessSampleSource final : public SampleSource {
 public:
  explicit InProcessSampleSource(const SampleSourceOptions& options);

  bool IsRemote() const override { return false; }
  absl::Status Connect() override { return absl::OkStatus(); }
  absl::StatusOr<TreeReport> Prepare(const TreeSpec& spec, uint64_t count,
                                     Progress* progress) override;
  absl::StatusOr<std::string> Sample(const SampleRequest& request, Progress* progress,
                                     const TreeCallback& on_tree,
                                     const BatchCallback& on_batch) override;
  absl::StatusOr<std::string> CacheStats() override;
  absl::StatusOr<bool> Serving() override;
  absl::StatusOr<std::string> UploadModel(const std::string& spec) override;
  absl::StatusOr<std::string> DescribeModel(const std::string& spec) override;
  absl::StatusOr<PreparedTree> LocalTree(const SampleRequest& request) override;

 private:
  const size_t batch_size_;
  DirectTreeSource trees_;
  FileModelSource files_;
  SamplingEngine engine_;
};

}  // namespace sfc

#endif  // SFCSAMPLER_CLIENT_CLI_IN_PROCESS_SAMPLE_SOURCE_H_
