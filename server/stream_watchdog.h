// Cuts streams that a blocked write or read would otherwise hold for good: a
// Sample reader that stopped reading, so that a write waits on HTTP/2 flow
// control past the timeout, or an uploader that stopped sending, so that a
// read waits past it. The synchronous API gives no timeout on Write or Read,
// so one thread looks at every watched stream a few times a second and
// cancels the ones that are due (ServerContext::TryCancel), which makes the
// blocked Write or Read return false at once and frees what the stream holds.
// Streams check their deadline between writes, so one may outlive it by at
// most a write timeout.
//
// Thread-safety: thread-safe. A Watch is used by its stream's thread.
#ifndef SFCSAMPLER_SERVER_STREAM_WATCHDOG_H_
#define SFCSAMPLER_SERVER_STREAM_WATCHDOG_H_

#include <chrono>
#include <memory>
#include <set>
#include <thread>

#include "absl/base/thread_annotations.h"
#include "absl/synchronization/mutex.h"
#include "grpcpp/server_context.h"

namespace sfc {

class StreamWatchdog {
 public:
  using Clock = std::chrono::steady_clock;
  enum class Reason { kNone, kWriteTimeout, kReadTimeout };

  // Watches one stream while it exists. Its stream calls BeginWrite() before
  // a Write and EndWrite() after it, or BeginRead() before a Read and
  // EndRead() after it.
  class Watch {
   public:
    ~Watch();
    Watch(const Watch&) = delete;
    Watch& operator=(const Watch&) = delete;
    void BeginWrite() ABSL_LOCKS_EXCLUDED(owner_->mu_);
    void EndWrite() ABSL_LOCKS_EXCLUDED(owner_->mu_);
    void BeginRead() ABSL_LOCKS_EXCLUDED(owner_->mu_);
    void EndRead() ABSL_LOCKS_EXCLUDED(owner_->mu_);
    // Why the watchdog cancelled the stream, or kNone. A cancelled stream's
    // client sees CANCELLED (a blocked stream cannot deliver a status); the
    // server logs and counts the reason.
    Reason reason() const ABSL_LOCKS_EXCLUDED(owner_->mu_);

   private:
    friend class StreamWatchdog;
    Watch(StreamWatchdog* owner, grpc::ServerContext* context) : owner_(owner), context_(context) {}
    StreamWatchdog* const owner_;
    grpc::ServerContext* const context_;
    void Begin(Reason due) ABSL_LOCKS_EXCLUDED(owner_->mu_);
    // Guarded by owner_->mu_.
    Reason waiting_ = Reason::kNone;  // the blocked call's reason to cut, if it lasts
    Clock::time_point wait_started_;
    Reason reason_ = Reason::kNone;
  };

  // timeout_seconds > 0: how long one Write or Read may block; the thread
  // looks every `period`.
  explicit StreamWatchdog(double timeout_seconds,
                          std::chrono::milliseconds period = std::chrono::milliseconds(50));
  ~StreamWatchdog();
  StreamWatchdog(const StreamWatchdog&) = delete;
  StreamWatchdog& operator=(const StreamWatchdog&) = delete;

  // Starts watching `context`'s stream. The Watch must be destroyed before
  // the context.
  std::unique_ptr<Watch> Start(grpc::ServerContext* context) ABSL_LOCKS_EXCLUDED(mu_);

  double timeout_seconds() const { return timeout_seconds_; }

 private:
  void Loop() ABSL_LOCKS_EXCLUDED(mu_);

  // Constant after construction.
  const double timeout_seconds_;
  const std::chrono::milliseconds period_;

  mutable absl::Mutex mu_;
  std::set<Watch*> watches_ ABSL_GUARDED_BY(mu_);
  bool stopping_ ABSL_GUARDED_BY(mu_) = false;
  std::thread thread_;
};

}  // namespace sfc

#endif  // SFCSAMPLER_SERVER_STREAM_WATCHDOG_H_
