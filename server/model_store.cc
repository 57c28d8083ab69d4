#include "server/model_store.h"

#include <algorithm>
#include <vector>

#include "absl/strings/str_format.h"
#include "base/echo.h"

namespace sfc {

namespace {

absl::Status TooLarge(uint64_t size, uint64_t max_model_bytes, uint64_t budget_bytes) {
  return absl::ResourceExhaustedError(absl::StrFormat(
      "the model is %d bytes or more, more than this server takes (max_model_bytes %d, model "
      "budget %d); simplify or split it, or ask the operator to raise the limit",
      size, max_model_bytes, budget_bytes));
}

}  // namespace

ModelStore::Upload::Upload(Upload&& other) noexcept
    : store_(other.store_),
      chunks_(std::move(other.chunks_)),
      whole_(std::move(other.whole_)),
      expected_(other.expected_),
      size_(other.size_),
      held_(other.held_) {
  other.chunks_.clear();
  other.whole_.clear();
  other.size_ = 0;
  other.held_ = 0;
}

ModelStore::Upload::~Upload() {
  if (held_ > 0) store_->Release(held_);
}

absl::Status ModelStore::Upload::Expect(uint64_t total_bytes) {
  if (total_bytes > std::min(store_->max_model_bytes_, store_->budget_bytes_)) {
    store_->CountRejected();
    return TooLarge(total_bytes, store_->max_model_bytes_, store_->budget_bytes_);
  }
  // Nothing is counted until the first chunk (Append): a client that opens
  // an upload and sends nothing holds nothing of the budget.
  expected_ = total_bytes;
  return absl::OkStatus();
}

absl::Status ModelStore::Upload::Append(std::string chunk) {
  if (expected_) {
    if (size_ + chunk.size() > *expected_) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "the upload sent more than the %d bytes it declared (total_bytes)", *expected_));
    }
    if (held_ < *expected_) {
      // The first chunk holds and allocates the declared size once: the
      // buffer never grows, so nothing is counted twice. An uploader that
      // then stops sending keeps it until the idle cut (the service's).
      if (absl::Status held = store_->Hold(*expected_); !held.ok()) return held;
      held_ = *expected_;
      whole_.reserve(*expected_);
    }
    whole_ += chunk;  // counted by the hold above
    size_ += chunk.size();
    return absl::OkStatus();
  }
  if (size_ + chunk.size() > std::min(store_->max_model_bytes_, store_->budget_bytes_)) {
    store_->CountRejected();
    return TooLarge(size_ + chunk.size(), store_->max_model_bytes_, store_->budget_bytes_);
  }
  if (absl::Status held = store_->Hold(chunk.size()); !held.ok()) return held;
  held_ += chunk.size();
  size_ += chunk.size();
  chunks_.push_back(std::move(chunk));
  return absl::OkStatus();
}

absl::StatusOr<std::string> ModelStore::Upload::Join() {
  if (expected_) {
    if (size_ != *expected_) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "the upload declared %d bytes (total_bytes) and sent %d", *expected_, size_));
    }
    return std::move(whole_);
  }
  if (chunks_.size() == 1 && chunks_[0].capacity() == size_) {
    std::string bytes = std::move(chunks_[0]);
    chunks_.clear();
    return bytes;
  }
  // The joined copy is counted before it exists, the chunks until they are gone.
  if (absl::Status held = store_->Hold(size_); !held.ok()) return held;
  held_ += size_;
  std::string bytes;
  bytes.reserve(size_);
  for (const std::string& chunk : chunks_) bytes += chunk;
  chunks_ = {};
  store_->Release(size_);
  held_ -= size_;
  return bytes;
}

ModelStore::ModelStore(uint64_t budget_bytes, uint64_t max_model_bytes)
    : budget_bytes_(budget_bytes), max_model_bytes_(max_model_bytes) {}

absl::StatusOr<StoredModel> ModelStore::Put(ModelFormat format, std::string bytes,
                                            const std::string& name, bool* already) {
  Upload upload = StartUpload();
  if (absl::Status appended = upload.Append(std::move(bytes)); !appended.ok()) {
    return absl::Status(
        appended.code(),
        absl::StrFormat("upload \"%s\": %s", Echo(name, kMaxNameEcho), appended.message()));
  }
  return Put(format, std::move(upload), name, already);
}

absl::StatusOr<StoredModel> ModelStore::Put(ModelFormat format, Upload upload,
                                            const std::string& name, bool* already) {
  auto bytes = upload.Join();
  if (!bytes.ok()) {
    return absl::Status(bytes.status().code(),
                        absl::StrFormat("upload \"%s\": %s", Echo(name, kMaxNameEcho),
                                        bytes.status().message()));
  }
  StoredModel model;
  model.format = format;
  model.sha256 = Sha256Hex(*bytes);
  // No name is kept: the model is shared by every client that sends these
  // bytes, and one client's file name must not show in another's errors.
  std::vector<std::string> evicted;
  {
    absl::MutexLock lock(&mu_);
    if (const StoredModel* stored = models_.Touch(model.sha256)) {
      ++stats_.already_stored;
      if (already) *already = true;
      StoredModel found = *stored;
      found.format = format;  // the same bytes may be named under another format
      return found;  // the upload gives back its hold
    }
    if (already) *already = false;
    model.bytes = std::make_shared<const std::string>(*std::move(bytes));
    ++stats_.uploads;
    // The upload's hold passes to the stored model.
    held_ -= upload.held_;
    upload.held_ = 0;
    models_.Insert(model.sha256, model, model.bytes->size());
    evicted = EvictForBudget(/*keep=*/1);  // the newest stays
  }
  NotifyEvicted(evicted);
  return model;
}

absl::Status ModelStore::Hold(uint64_t bytes) {
  std::vector<std::string> evicted;
  {
    absl::MutexLock lock(&mu_);
    if (held_ + bytes > budget_bytes_) {
      return absl::ResourceExhaustedError(absl::StrFormat(
          "uploads being received hold %d of this server's %d bytes for models; retry in a "
          "moment, or ask the operator to raise --model-bytes",
          held_, budget_bytes_));
    }
    held_ += bytes;
    evicted = EvictForBudget(/*keep=*/0);
  }
  NotifyEvicted(evicted);
  return absl::OkStatus();
}

void ModelStore::Release(uint64_t bytes) {
  absl::MutexLock lock(&mu_);
  held_ -= std::min(held_, bytes);
}

std::vector<std::string> ModelStore::EvictForBudget(size_t keep) {
  std::vector<std::string> evicted;
  while (models_.total_cost() + held_ > budget_bytes_ && models_.size() > keep) {
    evicted.push_back(models_.PopLeastRecent().key);
    ++stats_.evictions;
  }
  return evicted;
}

void ModelStore::NotifyEvicted(const std::vector<std::string>& evicted) const {
  if (!on_evict_) return;
  for (const std::string& sha256 : evicted) on_evict_(sha256);
}

absl::StatusOr<StoredModel> ModelStore::Resolve(const ModelSpec& spec) const {
  if (spec.sha256.empty()) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "this server opens no files; upload the model first (sfcsampler upload, or --server with "
        "%s:FILE uploads it for you) and name it %s:sha256=HASH",
        ModelFormatName(spec.format), ModelFormatName(spec.format)));
  }
  absl::MutexLock lock(&mu_);
  const StoredModel* stored = models_.Touch(spec.sha256);
  if (stored == nullptr) {
    return absl::NotFoundError(absl::StrFormat(
        "no model with sha256 %s is stored on this server (never uploaded, or evicted for the "
        "model budget); upload it again",
        spec.sha256));
  }
  StoredModel model = *stored;
  model.format = spec.format;
  return model;
}

void ModelStore::CountRejected() {
  absl::MutexLock lock(&mu_);
  ++stats_.rejected;
}

ModelStoreStats ModelStore::stats() const {
  absl::MutexLock lock(&mu_);
  ModelStoreStats s = stats_;
  s.models = models_.size();
  s.bytes = models_.total_cost();
  s.upload_bytes = held_;
  return s;
}

}  // namespace sfc
