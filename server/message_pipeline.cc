#include "server/message_pipeline.h"

#include <utility>

namespace sfc {

namespace v1 = ::sfcsampler::v1;

MessagePipeline::MessagePipeline(int depth, Produce produce)
    : depth_(static_cast<size_t>(depth < 0 ? 0 : depth)), produce_(std::move(produce)) {
  if (depth_ > 0) thread_ = std::thread([this] { Run(); });
}

MessagePipeline::~MessagePipeline() {
  {
    absl::MutexLock lock(&mu_);
    stopping_ = true;
  }
  if (thread_.joinable()) thread_.join();
}

void MessagePipeline::Step(std::unique_ptr<v1::SampleResponse> response, std::vector<Item>* out) {
  if (!response) response = std::make_unique<v1::SampleResponse>();
  response->clear_header();
  v1::SampleBatch* batch = response->mutable_batch();
  batch->Clear();
  absl::StatusOr<size_t> n = produce_(batch);
  if (!n.ok()) {
    out->push_back(Item{nullptr, 0, n.status()});
    ended_ = true;
    return;
  }
  if (*n > 0 || first_) out->push_back(Item{std::move(response), *n, absl::OkStatus()});
  if (*n == 0) {
    out->push_back(Item{nullptr, 0, absl::OkStatus()});
    ended_ = true;
  }
  first_ = false;
}

void MessagePipeline::Run() {
  std::vector<Item> made;
  while (!ended_) {
    std::unique_ptr<v1::SampleResponse> response;
    {
      absl::MutexLock lock(&mu_);
      auto room = [this]() ABSL_SHARED_LOCKS_REQUIRED(mu_) {
        return stopping_ || queue_.size() < depth_;
      };
      mu_.Await(absl::Condition(&room));
      if (stopping_) return;
      if (!free_.empty()) {
        response = std::move(free_.back());
        free_.pop_back();
      }
    }
    made.clear();
    Step(std::move(response), &made);
    absl::MutexLock lock(&mu_);
    for (Item& item : made) queue_.push_back(std::move(item));
  }
}

std::optional<MessagePipeline::Item> MessagePipeline::Next(absl::Duration timeout) {
  absl::MutexLock lock(&mu_);
  if (depth_ == 0 && queue_.empty() && !ended_) {
    // No producer thread: make the next message here, reusing a written one.
    std::unique_ptr<v1::SampleResponse> response;
    if (!free_.empty()) {
      response = std::move(free_.back());
      free_.pop_back();
    }
    std::vector<Item> made;
    Step(std::move(response), &made);
    for (Item& item : made) queue_.push_back(std::move(item));
  }
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
