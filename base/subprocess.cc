#include "base/subprocess.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/mman.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>

#include "absl/strings/str_cat.h"

extern char** environ;

namespace sfc {
namespace {

// Closes a descriptor when it leaves scope.
struct Fd {
  int fd = -1;
  ~Fd() {
    if (fd >= 0) ::close(fd);
  }
};

absl::Status Errno(absl::string_view what) {
  return absl::InternalError(absl::StrCat(what, ": ", std::strerror(errno)));
}

// Reads what is available from the non-blocking `fd` into `out`, up to
// `max` bytes; past that it reads and drops, and says so in `clipped`.
void Drain(int fd, size_t max, std::string* out, bool* clipped) {
  char buffer[65536];
  while (true) {
    const ssize_t n = ::read(fd, buffer, sizeof buffer);
    if (n <= 0) return;
    const size_t room = max - std::min(out->size(), max);
    if (static_cast<size_t>(n) > room) *clipped = true;
    out->append(buffer, std::min(static_cast<size_t>(n), room));
  }
}

}  // namespace

absl::StatusOr<SubprocessResult> RunSubprocess(const std::vector<std::string>& argv,
                                               absl::string_view input, size_t max_output,
                                               double wall_seconds,
                                               const std::function<absl::Status()>& check) {
  if (argv.empty()) return absl::InvalidArgumentError("no program to run");
  // The input in an in-memory file: the program reads it at its own pace.
  Fd in{::memfd_create("sfc-subprocess-input", MFD_CLOEXEC)};
  if (in.fd < 0) return Errno("memfd_create");
  for (size_t done = 0; done < input.size();) {
    const ssize_t n = ::write(in.fd, input.data() + done, input.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      return Errno("writing the subprocess's input");
    }
    done += static_cast<size_t>(n);
  }
  if (::lseek(in.fd, 0, SEEK_SET) != 0) return Errno("lseek");
  int out_pipe[2];
  if (::pipe2(out_pipe, O_CLOEXEC) != 0) return Errno("pipe2");
  Fd out_read{out_pipe[0]}, out_write{out_pipe[1]};
  // Only our end reads without blocking: the program's writes must block
  // while the pipe is full, not fail.
  if (::fcntl(out_read.fd, F_SETFL, O_NONBLOCK) != 0) return Errno("fcntl");
  ::fcntl(out_read.fd, F_SETPIPE_SZ, 1 << 20);  // fewer wake-ups for large outputs; may fail
  Fd null{::open("/dev/null", O_WRONLY | O_CLOEXEC)};
  if (null.fd < 0) return Errno("open /dev/null");

  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, in.fd, 0);
  posix_spawn_file_actions_adddup2(&actions, out_write.fd, 1);
  posix_spawn_file_actions_adddup2(&actions, null.fd, 2);
  // The child starts with default signal handling and no blocked signals,
  // whatever this process set up.
  posix_spawnattr_t attributes;
  posix_spawnattr_init(&attributes);
  sigset_t all, none;
  sigfillset(&all);
  sigemptyset(&none);
  posix_spawnattr_setsigdefault(&attributes, &all);
  posix_spawnattr_setsigmask(&attributes, &none);
  posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETSIGDEF | POSIX_SPAWN_SETSIGMASK);
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  pid_t pid = 0;
  const int spawned =
      posix_spawn(&pid, argv[0].c_str(), &actions, &attributes, args.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  posix_spawnattr_destroy(&attributes);
  if (spawned != 0) {
    return absl::InternalError(
        absl::StrCat("cannot start ", argv[0], ": ", std::strerror(spawned)));
  }
  ::close(out_write.fd);
  out_write.fd = -1;

  SubprocessResult result;
  const auto start = std::chrono::steady_clock::now();
  absl::Status stop;
  int status = 0;
  while (true) {
    Drain(out_read.fd, max_output, &result.output, &result.output_clipped);
    const pid_t done = ::waitpid(pid, &status, WNOHANG);
    if (done == pid) break;
    if (done < 0 && errno != EINTR) return Errno("waitpid");
    if (stop.ok() && check) stop = check();
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (stop.ok() && wall_seconds > 0 && elapsed > wall_seconds) result.timed_out = true;
    if (!stop.ok() || result.timed_out) {
      ::kill(pid, SIGKILL);
      while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
      }
      break;
    }
    // Wake for output at once, else every 2 ms to look at the process.
    pollfd ready{out_read.fd, POLLIN, 0};
    ::poll(&ready, 1, 2);
  }
  Drain(out_read.fd, max_output, &result.output, &result.output_clipped);
  if (!stop.ok()) return stop;
  result.exited = WIFEXITED(status);
  result.exit_code = result.exited ? WEXITSTATUS(status) : 0;
  result.signal = WIFSIGNALED(status) ? WTERMSIG(status) : 0;
  return result;
}

std::string FindSiblingProgram(const std::string& name) {
  std::error_code error;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", error);
  if (error) return "";
  for (const std::filesystem::path& dir :
       {self.parent_path(), self.parent_path().parent_path() / "server"}) {
    const std::string path = (dir / name).string();
    if (access(path.c_str(), X_OK) == 0) return path;
  }
  return "";
}

absl::StatusOr<std::string> ResolveProgramFlag(const std::string& flag, const std::string& name) {
  if (flag == "none") return std::string();
  if (flag == "auto") return FindSiblingProgram(name);
  if (access(flag.c_str(), X_OK) != 0) {
    return absl::FailedPreconditionError(absl::StrCat("cannot run ", flag, " (", name, ")"));
  }
  return flag;
}

}  // namespace sfc
