#include "server/stream_watchdog.h"

#include "absl/time/time.h"

namespace sfc {

StreamWatchdog::StreamWatchdog(double timeout_seconds, std::chrono::milliseconds period)
    : timeout_seconds_(timeout_seconds), period_(period) {
  thread_ = std::thread([this] { Loop(); });
}

StreamWatchdog::~StreamWatchdog() {
  {
    absl::MutexLock lock(&mu_);
    stopping_ = true;
  }
  thread_.join();
}

std::unique_ptr<StreamWatchdog::Watch> StreamWatchdog::Start(grpc::ServerContext* context) {
  auto watch = std::unique_ptr<Watch>(new Watch(this, context));
  absl::MutexLock lock(&mu_);
  watches_.insert(watch.get());
  return watch;
}

StreamWatchdog::Watch::~Watch() {
  absl::MutexLock lock(&owner_->mu_);
  owner_->watches_.erase(this);
}

void StreamWatchdog::Watch::Begin(Reason due) {
  absl::MutexLock lock(&owner_->mu_);
  waiting_ = due;
  wait_started_ = Clock::now();
}

void StreamWatchdog::Watch::BeginWrite() { Begin(Reason::kWriteTimeout); }
void StreamWatchdog::Watch::EndWrite() { Begin(Reason::kNone); }
void StreamWatchdog::Watch::BeginRead() { Begin(Reason::kReadTimeout); }
void StreamWatchdog::Watch::EndRead() { Begin(Reason::kNone); }

StreamWatchdog::Reason StreamWatchdog::Watch::reason() const {
  absl::MutexLock lock(&owner_->mu_);
  return reason_;
}

void StreamWatchdog::Loop() {
  const auto timeout = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(timeout_seconds_));
  absl::MutexLock lock(&mu_);
  while (!stopping_) {
    mu_.AwaitWithTimeout(absl::Condition(&stopping_), absl::FromChrono(period_));
    const auto now = Clock::now();
    for (Watch* w : watches_) {
      if (w->reason_ != Reason::kNone || w->waiting_ == Reason::kNone ||
          now - w->wait_started_ <= timeout) {
        continue;
      }
      w->reason_ = w->waiting_;
      // Thread-safe; the stream's blocked Write or Read returns false.
      w->context_->TryCancel();
    }
  }
}

}  // namespace sfc
