// Generation pipelined with writes for one Sample stream: a producer thread
// makes the stream's messages (generates a batch and converts it into its
// outgoing SampleResponse) while the stream's RPC thread writes the ones
// already made, so generation no longer waits for each blocking Write and
// Write no longer waits for generation.
//
// Depth 0 is no pipeline: Next() makes each message on the caller's thread,
// between writes (how streams ran before the pipeline; kept to measure it).
//
// Memory is bounded: at most `depth` finished messages wait in the queue,
// one is being made and one written, so a stream holds at most depth + 2
// messages (and its producer's one SampleBatch). Written messages come back
// through Recycle() and are reused, so a long stream allocates nothing after
// its first few batches. A reader that stops reading stops the producer as
// soon as the queue is full: nothing is generated further ahead.
//
// Thread-safety: Next() and Recycle() belong to the consumer (the RPC
// thread); the producer function runs on the pipeline's own thread only.
#ifndef SFCSAMPLER_SERVER_MESSAGE_PIPELINE_H_
#define SFCSAMPLER_SERVER_MESSAGE_PIPELINE_H_

#include <cstddef>
#include <deque>
#include <functional>
#include <memory>
#include <optional>
#include <thread>
#include <vector>

#include "absl/base/thread_annotations.h"
#include "absl/status/statusor.h"
#include "absl/synchronization/mutex.h"
#include "absl/time/time.h"
#include "sfcsampler/v1/sampler.pb.h"

namespace sfc {

class MessagePipeline {
 public:
  // Fills `batch` (cleared, capacity kept) with the stream's next batch and
  // returns its number of samples, 0 once the stream is exhausted; an error
  // ends the stream.
  using Produce = std::function<absl::StatusOr<size_t>(::sfcsampler::v1::SampleBatch* batch)>;

  // One message of the stream, or its end (`response` null): `status` says
  // whether it ended complete (OK) or with the producer's error.
  struct Item {
    std::unique_ptr<::sfcsampler::v1::SampleResponse> response;
    size_t samples = 0;
    absl::Status status;
  };

  // Starts the producer. The stream's first message is always made (with an
  // empty batch if there are no samples); later ones only while `produce`
  // returns samples. depth >= 0 (0: no producer thread, see above).
  MessagePipeline(int depth, Produce produce);
  // Stops the producer (it finishes the batch it is making) and joins it.
  ~MessagePipeline();
  MessagePipeline(const MessagePipeline&) = delete;
  MessagePipeline& operator=(const MessagePipeline&) = delete;

  // The next item, waiting at most `timeout` for it; nullopt if none came
  // in time (the caller checks its cancellation and deadline, then asks
  // again). After the end item there are no more.
  std::optional<Item> Next(absl::Duration timeout) ABSL_LOCKS_EXCLUDED(mu_);
  // Gives a written message back for reuse.
  void Recycle(std::unique_ptr<::sfcsampler::v1::SampleResponse> response) ABSL_LOCKS_EXCLUDED(mu_);

 private:
  void Run() ABSL_LOCKS_EXCLUDED(mu_);
  // Makes one message with `produce_` (in `response`, or a new one when
  // null) and appends what follows from it to `out`: the message (unless a
  // later empty one), then the end if the stream is over.
  void Step(std::unique_ptr<::sfcsampler::v1::SampleResponse> response, std::vector<Item>* out);

  // Constant after construction.
  const size_t depth_;
  const Produce produce_;

  absl::Mutex mu_;
  std::deque<Item> queue_ ABSL_GUARDED_BY(mu_);
  std::vector<std::unique_ptr<::sfcsampler::v1::SampleResponse>> free_ ABSL_GUARDED_BY(mu_);
  bool stopping_ ABSL_GUARDED_BY(mu_) = false;
  std::thread thread_;
  // The producer's own (Run's thread, or Next's caller at depth 0).
  bool first_ = true;
  bool ended_ = false;
};

}  // namespace sfc

#endif  // SFCSAMPLER_SERVER_MESSAGE_PIPELINE_H_
