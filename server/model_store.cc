#include "server/model_store.h"

#include <vector>

#include "absl/strings/str_format.h"
#include "base/echo.h"

namespace sfc {

ModelStore::ModelStore(uint64_t budget_bytes, uint64_t max_model_bytes)
    : budget_bytes_(budget_bytes), max_model_bytes_(max_model_bytes) {}

absl::StatusOr<StoredModel> ModelStore::Put(ModelFormat format, std::string bytes,
                                            const std::string& name, bool* already) {
  if (bytes.size() > max_model_bytes_ || bytes.size() > budget_bytes_) {
    CountRejected();
    return absl::ResourceExhaustedError(absl::StrFormat(
        "the model \"%s\" is %d bytes, more than this server takes (max_model_bytes %d, model "
        "budget %d); simplify or split it, or ask the operator to raise the limit",
        Echo(name, kMaxNameEcho), bytes.size(), std::min(max_model_bytes_, budget_bytes_),
        budget_bytes_));
  }
  StoredModel model;
  model.format = format;
  model.sha256 = Sha256Hex(bytes);
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
    return found;
  }
  if (already) *already = false;
  // An upload grows its string by doubling: up to twice its size reserved,
  // which the budget (counting the size) would not see.
  bytes.shrink_to_fit();
  model.bytes = std::make_shared<const std::string>(std::move(bytes));
  ++stats_.uploads;
  models_.Insert(model.sha256, model, model.bytes->size());
  while (models_.total_cost() > budget_bytes_ && models_.size() > 1) {  // the newest stays
    evicted.push_back(models_.PopLeastRecent().key);
    ++stats_.evictions;
  }
  }
  if (on_evict_) {
    for (const std::string& sha256 : evicted) on_evict_(sha256);
  }
  return model;
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
  return s;
}

}  // namespace sfc
