#include "server/stream_memory.h"

#include <utility>

#include "absl/strings/str_format.h"
#include "absl/time/time.h"
#include "base/status_macros.h"

namespace sfc {

StreamMemory::Reservation::Reservation(Reservation&& other) noexcept
    : owner_(std::exchange(other.owner_, nullptr)), bytes_(std::exchange(other.bytes_, 0)) {}

StreamMemory::Reservation& StreamMemory::Reservation::operator=(Reservation&& other) noexcept {
  if (this != &other) {
    if (owner_) owner_->Release(bytes_);
    owner_ = std::exchange(other.owner_, nullptr);
    bytes_ = std::exchange(other.bytes_, 0);
  }
  return *this;
}

StreamMemory::Reservation::~Reservation() {
  if (owner_) owner_->Release(bytes_);
}

absl::Status StreamMemory::CheckFits(uint64_t bytes, const char* what, const char* advice) const {
  if (bytes <= budget_) return absl::OkStatus();
  return absl::ResourceExhaustedError(absl::StrFormat(
      "%s needs %d bytes of working memory, more than this server's %d for all streams "
      "(stream_memory_bytes); %s",
      what, bytes, budget_, advice));
}

absl::StatusOr<StreamMemory::Reservation> StreamMemory::Reserve(
    uint64_t bytes, const char* what, const char* advice,
    const std::function<absl::Status()>& check) {
  RETURN_IF_ERROR(CheckFits(bytes, what, advice));
  absl::MutexLock lock(&mu_);
  bool waited = false;
  while (reserved_ + bytes > budget_) {
    if (!waited) ++waits_, waited = true;
    // Wakes when memory is released, or after a while to ask `check`.
    struct Fits {
      const uint64_t* reserved;
      uint64_t limit;
      bool Holds() const { return *reserved <= limit; }
    } fits{&reserved_, budget_ - bytes};
    mu_.AwaitWithTimeout(absl::Condition(&fits, &Fits::Holds), absl::Milliseconds(20));
    if (check) {
      mu_.Unlock();
      absl::Status status = check();
      mu_.Lock();
      if (!status.ok()) return status;
    }
  }
  reserved_ += bytes;
  return Reservation(this, bytes);
}

void StreamMemory::Release(uint64_t bytes) {
  absl::MutexLock lock(&mu_);
  reserved_ -= bytes;
}

uint64_t StreamMemory::reserved_bytes() const {
  absl::MutexLock lock(&mu_);
  return reserved_;
}

uint64_t StreamMemory::waits() const {
  absl::MutexLock lock(&mu_);
  return waits_;
}

}  // namespace sfc
