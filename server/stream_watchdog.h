// Cuts Sample streams that a blocked write would otherwise hold for good: a
// reader that stopped reading, so that a write waits on HTTP/2 flow control
// past the write timeout. The synchronous API gives no timeout on Write, so
// one thread looks at every watched stream a few times a second and cancels
// the ones that are due (ServerContext::TryCancel), which makes the blocked
// Write return false at once and frees the stream's slot. Streams check their
// deadline between writes, so one may outlive it by at most a write timeout.
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
  enum class Reason { kNone, kWriteTimeout };

  // Watches one stream while it exists. Its stream calls BeginWrite() before
  // a Write and EndWrite() after it.
  class Watch {
   public:
    ~Watch();
    Watch(const Watch&) = delete;
    Watch& operator=(const Watch&) = delete;
    void BeginWrite() ABSL_LOCKS_EXCLUDED(owner_->mu_);
    void EndWrite() ABSL_LOCKS_EXCLUDED(owner_->mu_);
    // Why the watchdog cancelled the stream, or kNone. A cancelled stream's
  // client sees CANCELLED (a blocked stream cannot deliver a status); the
  // server logs and counts the reason.
    Reason reason() const ABSL_LOCKS_EXCLUDED(owner_->mu_);

   private:
    friend class StreamWatchdog;
    Watch(StreamWatchdog* owner, grpc::ServerContext* context) : owner_(owner), context_(context) {}
    StreamWatchdog* const owner_;
    grpc::ServerContext* const context_;
    // Guarded by owner_->mu_.
    bool writing_ = false;
    Clock::time_point write_started_;
    Reason reason_ = Reason::kNone;
  };

  // write_timeout_seconds > 0; the thread looks every `period`.
  explicit StreamWatchdog(double write_timeout_seconds,
                          std::chrono::milliseconds period = std::chrono::milliseconds(50));
  ~StreamWatchdog();
  StreamWatchdog(const StreamWatchdog&) = delete;
  StreamWatchdog& operator=(const StreamWatchdog&) = delete;

  // Starts watching `context`'s stream. The Watch must be destroyed before
  // the context.
  std::unique_ptr<Watch> Start(grpc::ServerContext* context) ABSL_LOCKS_EXCLUDED(mu_);

  double write_timeout_seconds() const { return write_timeout_seconds_; }

 private:
  void Loop() ABSL_LOCKS_EXCLUDED(mu_);

  // Constant after construction.
  const double write_timeout_seconds_;
  const std::chrono::milliseconds period_;

  mutable absl::Mutex mu_;
  std::set<Watch*> watches_ ABSL_GUARDED_BY(mu_);
  bool stopping_ ABSL_GUARDED_BY(mu_) = false;
  std::thread thread_;
};

}  // namespace sfc

#endif  // SFCSAMPLER_SERVER_STREAM_WATCHDOG_H_
