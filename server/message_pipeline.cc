#include "server/message_pipeline.h"

#include <utility>

namespace sfc {

namespace v1 = ::sfcsampler::v1;

MessagePipeline::MessagePipeline(int depth, Produce produce)
    : depth_(static_cast<size_t>(depth < 1 ? 1 : depth)), produce_(std::move(produce)) {
  thread_ = std::thread([this] { Run(); });
}

MessagePipeline::~MessagePipeline() {
  {
    absl::MutexLock lock(&mu_);
    stopping_ = true;
  }
  thread_.join();
}

void MessagePipeline::Run() {
  bool first = true;
  while (true) {
    std::unique_ptr<v1::SampleResponse> response;
    {
      absl::MutexLock lock(&mu_);
      auto room = [this]() ABSL_SHARED_LOCKS_REQUIRED(mu_) { return stopping_ || queue_.size() < depth_; };
      mu_.Await(absl::Condition(&room));
      if (stopping_) return;
      if (!free_.empty()) {
        response = std::move(free_.back());
        free_.pop_back();
      }
    }
    if (!response) response = std::make_unique<v1::SampleResponse>();
    response->clear_header();
    v1::SampleBatch* batch = response->mutable_batch();
    batch->Clear();
    absl::StatusOr<size_t> n = produce_(batch);
    absl::MutexLock lock(&mu_);
    if (!n.ok()) {
      queue_.push_back(Item{nullptr, 0, n.status()});
      return;
    }
    if (*n > 0 || first) queue_.push_back(Item{std::move(response), *n, absl::OkStatus()});
    if (*n == 0) {
      queue_.push_back(Item{nullptr, 0, absl::OkStatus()});
      return;
    }
    first = false;
  }
}

std::optional<MessagePipeline::Item> MessagePipeline::Next(absl::Duration timeout) {
  absl::MutexLock lock(&mu_);
  auto ready = [this]() ABSL_SHARED_LOCKS_REQUIRED(mu_) { return !queue_.empty(); };
  if (!mu_.AwaitWithTimeout(absl::Condition(&ready), timeout)) return std::nullopt;
  Item item = std::move(queue_.front());
  queue_.pop_front();
  return item;
}

void MessagePipeline::Recycle(std::unique_ptr<v1::SampleResponse> response) {
  absl::MutexLock lock(&mu_);
  free_.push_back(std::move(response));
}

}  // namespace sfc
