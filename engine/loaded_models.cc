#include "engine/loaded_models.h"

namespace sfc {

std::shared_ptr<const void> LoadedModels::Find(const std::string& key) {
  absl::MutexLock lock(&mu_);
  auto it = entries_.find(key);
  if (it == entries_.end()) return nullptr;
  lru_.splice(lru_.begin(), lru_, it->second.lru);
  return it->second.model;
}

std::shared_ptr<const void> LoadedModels::Keep(const std::string& key,
                                               std::shared_ptr<const void> model) {
  absl::MutexLock lock(&mu_);
  if (auto it = entries_.find(key); it != entries_.end()) return it->second.model;
  lru_.push_front(key);
  entries_[key] = Entry{model, lru_.begin()};
  while (entries_.size() > capacity_) {
    entries_.erase(lru_.back());
    lru_.pop_back();
  }
  return model;
}

}  // namespace sfc
