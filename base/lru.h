// A least-recently-used map: entries keyed by Key, each with a cost (bytes,
// or 1 to count entries), kept in recency order. The building block of the
// server's tree cache and model store, the parsed-model cache and the Python
// bindings' recent trees. It evicts nothing by itself: the owner, which knows
// its budget, pops the least recently used entries (PopLeastRecent).
//
// Thread-compatible: the owner's lock guards it.
#ifndef SFCSAMPLER_BASE_LRU_H_
#define SFCSAMPLER_BASE_LRU_H_

#include <cstddef>
#include <cstdint>
#include <list>
#include <utility>

#include "absl/container/flat_hash_map.h"

namespace sfc {

template <typename Key, typename Value>
class Lru {
 public:
  struct Entry {
    Key key;
    Value value;
    uint64_t cost;
  };

  Lru() = default;
  // index_ points into recency_: a copy would point into the original.
  Lru(const Lru&) = delete;
  Lru& operator=(const Lru&) = delete;

  size_t size() const { return recency_.size(); }
  bool empty() const { return recency_.empty(); }
  // The sum of the costs of the entries kept.
  uint64_t total_cost() const { return total_cost_; }

  // The value under `key`, or nullptr; its recency is unchanged. The pointer
  // stays valid until that entry is erased or evicted.
  Value* Find(const Key& key) {
    auto it = index_.find(key);
    return it == index_.end() ? nullptr : &it->second->value;
  }
  const Value* Find(const Key& key) const {
    auto it = index_.find(key);
    return it == index_.end() ? nullptr : &it->second->value;
  }

  // Find, and the entry becomes the most recently used.
  Value* Touch(const Key& key) {
    auto it = index_.find(key);
    if (it == index_.end()) return nullptr;
    recency_.splice(recency_.begin(), recency_, it->second);
    return &it->second->value;
  }

  // Adds `value` under `key` as the most recently used entry, costing `cost`,
  // and returns true; evicts nothing (see PopLeastRecent). If `key` is kept
  // already, returns false and changes nothing (not even its recency).
  bool Insert(const Key& key, Value value, uint64_t cost) {
    if (index_.contains(key)) return false;
    recency_.push_front(Entry{key, std::move(value), cost});
    index_.emplace(key, recency_.begin());
    total_cost_ += cost;
    return true;
  }

  // Removes the entry under `key`; false if there was none.
  bool Erase(const Key& key) {
    auto it = index_.find(key);
    if (it == index_.end()) return false;
    total_cost_ -= it->second->cost;
    recency_.erase(it->second);
    index_.erase(it);
    return true;
  }

  // Removes every entry for which matches(key, value) is true.
  template <typename Matches>
  void EraseIf(Matches matches) {
    for (auto it = recency_.begin(); it != recency_.end();) {
      if (matches(static_cast<const Key&>(it->key), static_cast<const Value&>(it->value))) {
        total_cost_ -= it->cost;
        index_.erase(it->key);
        it = recency_.erase(it);
      } else {
        ++it;
      }
    }
  }

  // Removes the least recently used entry and returns it. REQUIRES: !empty().
  // The owner evicts with it while over its budget, e.g.
  //   while (!lru.empty() && lru.total_cost() > budget) Drop(lru.PopLeastRecent());
  Entry PopLeastRecent() {
    Entry entry = std::move(recency_.back());
    index_.erase(entry.key);
    recency_.pop_back();
    total_cost_ -= entry.cost;
    return entry;
  }

 private:
  std::list<Entry> recency_;  // front: most recently used
  absl::flat_hash_map<Key, typename std::list<Entry>::iterator> index_;
  uint64_t total_cost_ = 0;
};

}  // namespace sfc

#endif  // SFCSAMPLER_BASE_LRU_H_
