// Models held in memory for the embedded engine: meshes handed over as NumPy
// arrays reach the engine as the canonical PLY bytes the Python package
// writes for them (python/sfcsampler/meshes.py), under their SHA-256, with no
// file. A request names such a model as "ply:sha256=<hex>", exactly as it
// names an uploaded model on a server, so the model, its tree key and its
// samples are those of the same bytes read from a file or uploaded.
//
// A model is held while a call that needs it runs (Hold ... Release, counted,
// so concurrent calls on one model share it); the engine's own caches keep
// what it parsed. Other specs go to the local files, as in the CLI.
//
// Thread-safety: thread-safe.
#ifndef SFCSAMPLER_PYTHON_BINDINGS_MEMORY_MODELS_H_
#define SFCSAMPLER_PYTHON_BINDINGS_MEMORY_MODELS_H_

#include <memory>
#include <string>
#include <unordered_map>

#include "absl/base/thread_annotations.h"
#include "absl/status/statusor.h"
#include "absl/synchronization/mutex.h"
#include "engine/model_source.h"

namespace sfc::python {

class MemoryModelSource final : public ModelSource {
 public:
  MemoryModelSource() = default;
  MemoryModelSource(const MemoryModelSource&) = delete;
  MemoryModelSource& operator=(const MemoryModelSource&) = delete;

  // Holds `bytes` as a model of `format` called `name` (for messages) and
  // returns its canonical spec "FORMAT:sha256=<hex>". Each Hold needs one
  // Release of the returned spec.
  std::string Hold(ModelFormat format, std::string bytes, std::string name)
      ABSL_LOCKS_EXCLUDED(mu_);
  void Release(const std::string& spec) ABSL_LOCKS_EXCLUDED(mu_);

  // A held model for a sha256 reference (NOT_FOUND naming the hash when it is
  // not held), a local file otherwise.
  absl::StatusOr<StoredModel> Resolve(const ModelSpec& spec) const override
      ABSL_LOCKS_EXCLUDED(mu_);

 private:
  struct Held {
    StoredModel model;
    int holds = 0;
  };
  FileModelSource files_;
  mutable absl::Mutex mu_;
  std::unordered_map<std::string, Held> held_ ABSL_GUARDED_BY(mu_);  // by spec
};

}  // namespace sfc::python

#endif  // SFCSAMPLER_PYTHON_BINDINGS_MEMORY_MODELS_H_
