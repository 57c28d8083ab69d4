// SampleSource: where the CLI's samples and trees come from, the sampler in
// this process (InProcessSampleSource) or an sfcsampler-server over gRPC
// (ServerSampleSource), so that a subcommand is written once for both.
// Both give the same samples for the same request. It holds only what both
// can do; a subcommand that needs a server (cache, health, upload) takes the
// client itself (ConnectClient, connection_flags.h), and one that needs the
// sampler in this process (inspect's model table, render's curve tree) takes
// its engine (InProcessSampleSource::engine()).
//
// Thread-safety: Sample() may be called from several threads at once;
// Prepare() from one thread.
#ifndef SFCSAMPLER_CLIENT_CLI_SAMPLE_SOURCE_H_
#define SFCSAMPLER_CLIENT_CLI_SAMPLE_SOURCE_H_

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "client/cli/connection_flags.h"
#include "client/cli/progress.h"
#include "client/cli/tree_summary.h"
#include "client/sample_writer.h"
#include "core/types/sample_batch.h"
#include "request/sample_request.h"

namespace sfc {

struct SampleSourceOptions {
  // Samples per batch; 0: kDefaultBatchSize in process (request/stream_options.h),
  // the server's choice over the wire.
  size_t batch_size = 0;
  // The precision the samples are written in: float32 lets a server send
  // float32 columns (half the bytes; the writer rounds the same way).
  OutputPrecision precision = OutputPrecision::kFloat64;
  // In process: threads filling one batch; 0 = the hardware's, at most 4.
  int generation_threads = 0;
  // In process: a program that reads each CAD file in a process of its own
  // (kinds/cad/model_check.h) with model_parse_seconds of CPU (0 = no limit);
  // "" = read CAD files in this process.
  std::string model_check_program;
  double model_parse_seconds = 0;
};

class SampleSource {
 public:
  // The tree once it is known: before the first batch in process, with it
  // over the wire (so not at all for a stream with no samples).
  using TreeCallback = std::function<void(const TreeReport&)>;
  // A batch in curve order, with the set's size when known (not for a region).
  using BatchCallback =
      std::function<absl::Status(std::optional<uint64_t> expected, const SampleBatch&)>;

  virtual ~SampleSource() = default;

  // Builds (or warms) the tree for `spec` sized for `count` samples;
  // `progress` shows the wait.
  virtual absl::StatusOr<TreeReport> Prepare(const TreeSpec& spec, uint64_t count,
                                             Progress* progress) = 0;

  // Streams every sample of `request` in curve order to `on_batch` (whose
  // error ends the stream and is returned); `on_tree` (may be empty) gets the
  // tree, `progress` shows the wait and the stream. Returns where the samples
  // came from, e.g. "(sfcsampler-3, seed 1)" or "from HOST:PORT (...)".
  virtual absl::StatusOr<std::string> Sample(const SampleRequest& request, Progress* progress,
                                             const TreeCallback& on_tree,
                                             const BatchCallback& on_batch) = 0;
};

// The server `connection` names, its client connected now (reading the
// token and TLS files), or the in-process sampler when it names none.
absl::StatusOr<std::unique_ptr<SampleSource>> OpenSampleSource(
    const ConnectionFlags& connection, const SampleSourceOptions& options = {});

// Every sample of `request`, in curve order, in one batch; nothing on stderr.
absl::StatusOr<SampleBatch> CollectSamples(SampleSource& source, const SampleRequest& request);

}  // namespace sfc

#endif  // SFCSAMPLER_CLIENT_CLI_SAMPLE_SOURCE_H_
