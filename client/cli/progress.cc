#include "client/cli/progress.h"

#include <unistd.h>

#include <cstdio>

#include "absl/strings/str_format.h"

namespace sfc {

Progress::Progress(bool enabled) : enabled_(enabled && isatty(STDERR_FILENO)) {}

Progress::~Progress() { Done(); }

void Progress::Draw(const std::string& text) {
  // Pad over what was there, then return to the line's start.
  std::string line = "\r" + text;
  if (text.size() < drawn_) line.append(drawn_ - text.size(), ' ');
  std::fputs(line.c_str(), stderr);
  std::fflush(stderr);
  drawn_ = text.size();
}

void Progress::StartPhase(const std::string& label) {
  if (!enabled_) return;
  EndPhase();
  std::lock_guard<std::mutex> lock(mu_);
  phase_running_ = true;
  ticker_ = std::thread([this, label] {
    const auto start = std::chrono::steady_clock::now();
    std::unique_lock<std::mutex> lock(mu_);
    if (wake_.wait_for(lock, std::chrono::milliseconds(500), [this] { return !phase_running_; }))
      return;
    while (phase_running_) {
      Draw(absl::StrFormat(
          "%s... %.1f s", label,
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()));
      wake_.wait_for(lock, std::chrono::milliseconds(200), [this] { return !phase_running_; });
    }
  });
}

void Progress::EndPhase() {
  if (!enabled_) return;
  {
    std::lock_guard<std::mutex> lock(mu_);
    phase_running_ = false;
  }
  wake_.notify_all();
  if (ticker_.joinable()) ticker_.join();
  std::lock_guard<std::mutex> lock(mu_);
  if (drawn_ > 0) {  // clear the phase's line for what follows
    Draw("");
    std::fputs("\r", stderr);
    drawn_ = 0;
  }
}

void Progress::Samples(uint64_t done, uint64_t total) {
  if (!enabled_) return;
  EndPhase();
  const auto now = std::chrono::steady_clock::now();
  std::lock_guard<std::mutex> lock(mu_);
  if (!streaming_) {
    streaming_ = true;
    stream_start_ = now;
  } else if (now - last_draw_ < std::chrono::milliseconds(100) && done != total) {
    return;
  }
  last_draw_ = now;
  const double seconds = std::chrono::duration<double>(now - stream_start_).count();
  const std::string rate =
      seconds > 0.05 ? absl::StrFormat(", %.1f M/s", done / seconds / 1e6) : "";
  Draw(total
           ? absl::StrFormat("%d / %d samples (%.0f%%)%s", done, total, 100.0 * done / total, rate)
           : absl::StrFormat("%d samples%s", done, rate));
}

void Progress::Done() {
  if (!enabled_) return;
  EndPhase();  // also clears the line
  streaming_ = false;
}

}  // namespace sfc
