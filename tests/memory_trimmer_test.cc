// MemoryTrimmer gives freed heap pages back: resident memory falls after a
// pass where, without one, glibc would keep it.
#include "server/memory_trimmer.h"

#include <algorithm>
#include <chrono>
#include <fstream>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "gtest/gtest.h"

namespace sfc {
namespace {

// RssAnon of this process, bytes (0 where /proc is missing).
uint64_t AnonymousResidentBytes() {
  std::ifstream status("/proc/self/status");
  std::string key;
  uint64_t kb = 0;
  while (status >> key) {
    if (key == "RssAnon:") {
      status >> kb;
      return kb * 1024;
    }
    status.ignore(1 << 20, '\n');
  }
  return 0;
}

TEST(MemoryTrimmer, FreedSmallBlocksLeaveResidentMemoryAfterATrimPass) {
  if (AnonymousResidentBytes() == 0) GTEST_SKIP() << "no /proc/self/status";
  // 96 MB of 1 KiB blocks (below any mmap threshold: they live in the heap),
  // then all but every 64th freed: the survivors pin the heap's top, so only
  // a trim of the free pages inside it can give them back.
  constexpr size_t kBlock = 1024, kBlocks = 96 * 1024;
  std::vector<std::unique_ptr<char[]>> blocks(kBlocks);
  for (auto& b : blocks) {
    b.reset(new char[kBlock]);
    std::fill(b.get(), b.get() + kBlock, 1);  // resident
  }
  for (size_t i = 0; i < kBlocks; ++i) {
    if (i % 64 != 0) blocks[i].reset();
  }
  const uint64_t before = AnonymousResidentBytes();
  MemoryTrimmer::TrimNow();
  const uint64_t after = AnonymousResidentBytes();
  // At least half of the 94.5 MB freed goes back.
  EXPECT_LT(after + 45 * 1024 * 1024, before) << "before " << before << " after " << after;
}

TEST(MemoryTrimmer, TheBackgroundThreadRunsPassesAndStopsOnDestruction) {
  MemoryTrimmer trimmer(std::chrono::milliseconds(10));
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (trimmer.passes() < 3 && std::chrono::steady_clock::now() < until) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  EXPECT_GE(trimmer.passes(), 3u);
}  // the destructor joins: a hang here fails the test by its timeout

}  // namespace
}  // namespace sfc
