// Progress lines on stderr while the CLI works, only when stderr is a
// terminal: a ticking "building the curve tree... 2.4 s" during a phase with
// no countable steps (a tree build, a server's first answer), and
// "123456 / 1000000 samples, 2.1 M/s" during a stream. Each line is redrawn
// in place with '\r' and cleared when done; logs and pipes get nothing.
//
// Thread-safety: the methods are called from one thread; a phase's ticker
// runs on its own thread and shares the line under a mutex.
#ifndef SFCSAMPLER_CLIENT_CLI_PROGRESS_H_
#define SFCSAMPLER_CLIENT_CLI_PROGRESS_H_

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <string>
#include <thread>

namespace sfc {

class Progress {
 public:
  // Draws only if `enabled` and stderr is a terminal.
  explicit Progress(bool enabled);
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  // Shows "<label>... S s", redrawn every 0.2 s after the first 0.5 s (fast
  // phases draw nothing), until EndPhase() or the next Samples().
  void StartPhase(const std::string& label);
  void EndPhase();

  // `done` of `total` samples (total 0 = unknown, e.g. a region); redrawn at
  // most 10 times a second.
  void Samples(uint64_t done, uint64_t total);

  // Ends any phase and clears the line.
  void Done();

 private:
  void Draw(const std::string& text);  // REQUIRES: mu_ held

  const bool enabled_;
  std::mutex mu_;
  std::condition_variable wake_;
  bool phase_running_ = false;
  std::thread ticker_;
  size_t drawn_ = 0;  // characters on the line now
  std::chrono::steady_clock::time_point stream_start_, last_draw_;
  bool streaming_ = false;
};

}  // namespace sfc

#endif  // SFCSAMPLER_CLIENT_CLI_PROGRESS_H_
