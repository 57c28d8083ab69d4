// RunSubprocess (base/subprocess.h): input in, output out (capped), exit
// codes and signals told apart, and a program that blocks or that the
// caller gives up on is killed.
#include "base/subprocess.h"

#include <signal.h>

#include <atomic>
#include <chrono>
#include <string>

#include "gtest/gtest.h"

namespace sfc {
namespace {

double SecondsOf(const std::function<void()>& work) {
  const auto start = std::chrono::steady_clock::now();
  work();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

TEST(Subprocess, PassesInputAndOutputAndTheExitCode) {
  // Larger than a pipe's buffer: the program's writes block until read.
  const std::string input(3 << 20, 'x');
  auto cat = RunSubprocess({"/bin/cat"}, input, 4 << 20, 10, nullptr);
  ASSERT_TRUE(cat.ok()) << cat.status();
  EXPECT_TRUE(cat->exited);
  EXPECT_EQ(cat->exit_code, 0);
  EXPECT_TRUE(cat->output == input) << cat->output.size() << " bytes came back";
  EXPECT_FALSE(cat->output_clipped);

  auto clipped = RunSubprocess({"/bin/cat"}, input, 1000, 10, nullptr);
  ASSERT_TRUE(clipped.ok());
  EXPECT_EQ(clipped->output.size(), 1000u);
  EXPECT_TRUE(clipped->output_clipped);
  EXPECT_EQ(clipped->exit_code, 0) << "the rest was read and dropped, so cat finished";

  auto failing = RunSubprocess({"/bin/sh", "-c", "echo no; exit 3"}, "", 100, 10, nullptr);
  ASSERT_TRUE(failing.ok());
  EXPECT_EQ(failing->exit_code, 3);
  EXPECT_EQ(failing->output, "no\n");

  auto killed = RunSubprocess({"/bin/sh", "-c", "kill -SEGV $$"}, "", 100, 10, nullptr);
  ASSERT_TRUE(killed.ok());
  EXPECT_FALSE(killed->exited);
  EXPECT_EQ(killed->signal, SIGSEGV);

  EXPECT_EQ(RunSubprocess({"/no/such/program"}, "", 100, 10, nullptr).status().code(),
            absl::StatusCode::kInternal);
}

// A program that blocks uses no CPU, so only the wall clock ends it.
TEST(Subprocess, AProgramThatBlocksIsKilledAtTheWallClockLimit) {
  absl::StatusOr<SubprocessResult> run;
  const double seconds = SecondsOf([&] {
    run = RunSubprocess({"/bin/sleep", "100"}, "", 100, 0.3, nullptr);
  });
  ASSERT_TRUE(run.ok()) << run.status();
  EXPECT_TRUE(run->timed_out);
  EXPECT_FALSE(run->exited);
  EXPECT_EQ(run->signal, SIGKILL);
  EXPECT_LT(seconds, 5.0);
}

TEST(Subprocess, TheCallersCheckStopsTheProgram) {
  std::atomic<int> asked{0};
  absl::StatusOr<SubprocessResult> run;
  const double seconds = SecondsOf([&] {
    run = RunSubprocess({"/bin/sleep", "100"}, "", 100, 0, [&]() -> absl::Status {
      return ++asked > 20 ? absl::CancelledError("client gone") : absl::OkStatus();
    });
  });
  EXPECT_EQ(run.status().code(), absl::StatusCode::kCancelled);
  EXPECT_LT(seconds, 5.0);
}

}  // namespace
}  // namespace sfc
