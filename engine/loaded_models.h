// Parsed models (meshes, CAD models), kept so that requests for one model do
// not parse its file again: a tree found in the cache still needs its model
// to place samples on. Keyed by the model's canonical spec plus whatever
// changes the parse (a weight property, say); bounded by a count, least
// recently used first out. A model in use stays alive through its
// shared_ptr after it leaves this cache.
//
// Two requests that miss at once may both parse; the first to finish is kept.
//
// Thread-safety: thread-safe.
#ifndef SFCSAMPLER_ENGINE_LOADED_MODELS_H_
#define SFCSAMPLER_ENGINE_LOADED_MODELS_H_

#include <functional>
#include <list>
#include <memory>
#include <string>
#include <unordered_map>

#include "absl/base/thread_annotations.h"
#include "absl/status/statusor.h"
#include "absl/synchronization/mutex.h"

namespace sfc {

class LoadedModels {
 public:
  explicit LoadedModels(size_t capacity = 8) : capacity_(capacity) {}

  // The model under `key`, parsed by `load` if not kept. Errors are load's,
  // and are not kept (the next request parses again).
  template <typename Model>
  absl::StatusOr<std::shared_ptr<const Model>> Get(
      const std::string& key, const std::function<absl::StatusOr<std::shared_ptr<const Model>>()>& load) {
    if (auto kept = Find(key)) return std::static_pointer_cast<const Model>(kept);
    auto loaded = load();
    if (!loaded.ok()) return loaded.status();
    return std::static_pointer_cast<const Model>(Keep(key, *loaded));
  }

 private:
  std::shared_ptr<const void> Find(const std::string& key) ABSL_LOCKS_EXCLUDED(mu_);
  // Keeps `model` under `key` unless another is kept there already; returns the kept one.
  std::shared_ptr<const void> Keep(const std::string& key, std::shared_ptr<const void> model)
      ABSL_LOCKS_EXCLUDED(mu_);

  struct Entry {
    std::shared_ptr<const void> model;
    std::list<std::string>::iterator lru;
  };
  const size_t capacity_;
  absl::Mutex mu_;
  std::unordered_map<std::string, Entry> entries_ ABSL_GUARDED_BY(mu_);
  std::list<std::string> lru_ ABSL_GUARDED_BY(mu_);  // front: most recently used
};

}  // namespace sfc

#endif  // SFCSAMPLER_ENGINE_LOADED_MODELS_H_
