// The stream pipeline of server/message_pipeline.h on its own: messages come
// out in order and complete, an error ends the stream after the messages
// before it, the producer never runs more than depth + 1 messages ahead of a
// consumer that takes nothing, and stopping it does not wait for a reader.
#include "server/message_pipeline.h"

#include <atomic>
#include <chrono>
#include <thread>

#include "gtest/gtest.h"

namespace sfc {
namespace {

namespace v1 = ::sfcsampler::v1;

// A producer of `total` samples in batches of `batch`, each sample's index
// its number; counts its calls.
MessagePipeline::Produce Counting(uint64_t total, uint64_t batch, std::atomic<int>* calls) {
  auto next = std::make_shared<uint64_t>(0);
  return [=](v1::SampleBatch* out) -> absl::StatusOr<size_t> {
    ++*calls;
    const uint64_t n = std::min(batch, total - *next);
    out->set_first_index(*next);
    out->set_size(static_cast<uint32_t>(n));
    *next += n;
    return n;
  };
}

// Drains the pipeline: the items in order, the last being the end.
std::vector<MessagePipeline::Item> Drain(MessagePipeline& pipeline) {
  std::vector<MessagePipeline::Item> items;
  while (true) {
    auto item = pipeline.Next(absl::Seconds(5));
    EXPECT_TRUE(item.has_value()) << "no item within 5 s";
    if (!item) break;
    const bool end = item->response == nullptr;
    items.push_back(std::move(*item));
    if (end) break;
  }
  return items;
}

TEST(MessagePipeline, DeliversEveryBatchInOrderThenTheEnd) {
  for (int depth : {0, 1, 2, 5}) {
    for (uint64_t total : {0u, 1u, 7u, 100u, 101u}) {
      std::atomic<int> calls{0};
      MessagePipeline pipeline(depth, Counting(total, 10, &calls));
      std::vector<MessagePipeline::Item> items = Drain(pipeline);
      ASSERT_FALSE(items.empty());
      EXPECT_TRUE(items.back().status.ok());
      EXPECT_EQ(items.back().response, nullptr);
      uint64_t next = 0;
      for (size_t i = 0; i + 1 < items.size(); ++i) {
        EXPECT_EQ(items[i].response->batch().first_index(), next);
        EXPECT_EQ(items[i].samples, items[i].response->batch().size());
        next += items[i].samples;
        // Only the first message may be empty (it carries the header).
        if (i > 0) EXPECT_GT(items[i].samples, 0u);
        pipeline.Recycle(std::move(items[i].response));
      }
      EXPECT_EQ(next, total);
      EXPECT_EQ(items.size(), (total == 0 ? 1 : (total + 9) / 10) + 1) << "depth " << depth;
    }
  }
}

TEST(MessagePipeline, AnErrorEndsTheStreamAfterTheMessagesBeforeIt) {
  for (int depth : {0, 2}) {
    int call = 0;
    MessagePipeline pipeline(depth, [&](v1::SampleBatch* out) -> absl::StatusOr<size_t> {
      if (++call == 3) return absl::InvalidArgumentError("not finite at a sample");
      out->set_size(5);
      return 5;
    });
    std::vector<MessagePipeline::Item> items = Drain(pipeline);
    ASSERT_EQ(items.size(), 3u);
    EXPECT_EQ(items[0].samples + items[1].samples, 10u);
    EXPECT_EQ(items[2].response, nullptr);
    EXPECT_EQ(items[2].status.code(), absl::StatusCode::kInvalidArgument);
  }
}

TEST(MessagePipeline, WithoutAPipelineNothingIsMadeBeforeItIsAskedFor) {
  std::atomic<int> calls{0};
  MessagePipeline pipeline(0, Counting(uint64_t{1} << 40, 1000, &calls));
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  EXPECT_EQ(calls.load(), 0);
  for (int i = 1; i <= 3; ++i) {
    ASSERT_TRUE(pipeline.Next(absl::ZeroDuration()).has_value());
    EXPECT_EQ(calls.load(), i);
  }
}

TEST(MessagePipeline, AConsumerThatTakesNothingStopsTheProducerAtTheDepth) {
  for (int depth : {1, 3}) {
    std::atomic<int> calls{0};
    MessagePipeline pipeline(depth, Counting(uint64_t{1} << 40, 1000, &calls));
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    // depth messages queued; the producer waits for room before making more.
    EXPECT_EQ(calls.load(), depth);
    // Taking one lets exactly one more be made.
    auto item = pipeline.Next(absl::Seconds(1));
    ASSERT_TRUE(item.has_value());
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    EXPECT_EQ(calls.load(), depth + 1);
  }
}

TEST(MessagePipeline, StopsAtOnceWhenTheStreamEndsEarly) {
  std::atomic<int> calls{0};
  const auto start = std::chrono::steady_clock::now();
  {
    MessagePipeline pipeline(2, Counting(uint64_t{1} << 40, 1000, &calls));
    auto item = pipeline.Next(absl::Seconds(1));
    ASSERT_TRUE(item.has_value());
    // The consumer leaves with the producer waiting for room.
  }
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::milliseconds(1000));
}

TEST(MessagePipeline, NextGivesUpAfterItsTimeoutWhileABatchIsMade) {
  std::atomic<bool> release{false};
  MessagePipeline pipeline(1, [&](v1::SampleBatch* out) -> absl::StatusOr<size_t> {
    while (!release) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    out->set_size(1);
    return 0;
  });
  EXPECT_FALSE(pipeline.Next(absl::Milliseconds(20)).has_value());
  release = true;
  EXPECT_TRUE(pipeline.Next(absl::Seconds(5)).has_value());
}

}  // namespace
}  // namespace sfc
