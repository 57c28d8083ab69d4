// MemoryTrimmer gives freed heap pages back: resident memory falls after a
// pass where, without one, glibc would keep it. SetServerMallocOptions keeps
// a stream's message-sized buffers in the heap and maps large ones apart.
#include "server/memory_trimmer.h"

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "gtest/gtest.h"

#if defined(__GLIBC__)
#include <malloc.h>
#endif

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

#if defined(__GLIBC__)
TEST(SetServerMallocOptions, AStreamsMessageBuffersStayInTheHeapAndLargeOnesGoBack) {
  SetServerMallocOptions();
  // A float32 message of 65536 samples (1.3 MB) comes from the heap, and its
  // pages stay resident at the heap's top when it is freed, for the next
  // message (with the old fixed 1 MiB threshold it was a mapping of its own,
  // and glibc's default heap top of 128 KiB would not have kept it either).
  constexpr size_t kMessage = 1'310'720;
  const size_t mapped = mallinfo2().hblks;
  char* volatile message = static_cast<char*>(std::malloc(kMessage));  // volatile: not elided
  for (size_t i = 0; i < kMessage; i += 4096) message[i] = 1;
  EXPECT_EQ(mallinfo2().hblks, mapped);
  std::free(message);
  EXPECT_GE(mallinfo2().keepcost, kMessage);
  // A buffer of 4 MiB or more is its own mapping, given back when freed.
  void* volatile large = std::malloc(8 << 20);
  EXPECT_EQ(mallinfo2().hblks, mapped + 1);
  std::free(large);
  EXPECT_EQ(mallinfo2().hblks, mapped);
}
#endif

}  // namespace
}  // namespace sfc
