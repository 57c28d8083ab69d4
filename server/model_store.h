// The server's store of uploaded models (CAD files and meshes), keyed by the
// SHA-256 of their bytes, so a model travels once and every job shares it
// and its trees (docs/SERVICE.md). The server never opens a path a client sends:
// models reach it only through UploadModel.
//
// Bounded: one model may hold at most max_model_bytes (larger uploads are
// RESOURCE_EXHAUSTED and stop being read at that point), and all models
// together budget_bytes, past which the least recently used are evicted.
// Uploads being received count against the same budget as they arrive, or
// at their first chunk at the size they declare (Upload), so the bytes in
// flight plus the stored ones never pass it. A
// request naming an evicted model gets NOT_FOUND that says to upload it again;
// a tree or stream that uses a model keeps its bytes alive.
//
// Thread-safety: thread-safe.
#ifndef SFCSAMPLER_SERVER_MODEL_STORE_H_
#define SFCSAMPLER_SERVER_MODEL_STORE_H_

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "absl/base/thread_annotations.h"
#include "absl/synchronization/mutex.h"
#include "base/lru.h"
#include "engine/model_source.h"

namespace sfc {

struct ModelStoreStats {
  uint64_t models = 0;
  uint64_t bytes = 0;
  uint64_t uploads = 0;          // accepted uploads
  uint64_t already_stored = 0;   // uploads whose bytes were stored already
  uint64_t rejected = 0;         // uploads past max_model_bytes
  uint64_t evictions = 0;
  uint64_t upload_bytes = 0;     // held by uploads being received, now
};

class ModelStore final : public ModelSource {
 public:
  // An upload being received: its bytes, counted against the store's budget
  // from the moment they arrive until Put stores them or the upload is
  // dropped. Move-only; not thread-safe (one RPC's).
  class Upload {
   public:
    Upload(Upload&& other) noexcept;
    Upload& operator=(Upload&&) = delete;
    Upload(const Upload&) = delete;
    ~Upload();  // gives back what it holds

    // Declares the model's size before the first chunk. Nothing is counted
    // yet; the first Append counts and allocates the whole size once, and no
    // join is needed at the end. RESOURCE_EXHAUSTED when the size is past
    // max_model_bytes or the budget; the upload must then send exactly this
    // many bytes (INVALID_ARGUMENT otherwise).
    absl::Status Expect(uint64_t total_bytes);
    // Appends the next chunk (with Expect, the first one holds the declared
    // size). RESOURCE_EXHAUSTED when the model would pass max_model_bytes or
    // the budget, or when other uploads hold so much of the budget that this
    // chunk (or the declared size) does not fit (stored models are evicted
    // first); the upload then holds nothing more.
    absl::Status Append(std::string chunk);
    uint64_t size() const { return size_; }

   private:
    friend class ModelStore;
    explicit Upload(ModelStore* store) : store_(store) {}
    // The bytes as one string of exactly their size. While it is built the
    // chunks and the string are both counted.
    absl::StatusOr<std::string> Join();

    ModelStore* store_;
    std::vector<std::string> chunks_;  // exact sizes: no growth by doubling
    std::string whole_;                // with Expect: allocated at its full size
    std::optional<uint64_t> expected_;  // with Expect: the declared size
    uint64_t size_ = 0;
    uint64_t held_ = 0;  // counted against the store's budget now
  };

  ModelStore(uint64_t budget_bytes, uint64_t max_model_bytes);

  Upload StartUpload() { return Upload(this); }

  // Stores what `upload` received, as Put(format, bytes, ...) does; the
  // upload's hold on the budget passes to the stored model.
  absl::StatusOr<StoredModel> Put(ModelFormat format, Upload upload, const std::string& name,
                                  bool* already = nullptr) ABSL_LOCKS_EXCLUDED(mu_);

  // Stores `bytes` as a model of `format` (or finds it stored). `already`
  // says whether it was. RESOURCE_EXHAUSTED past max_model_bytes or the
  // budget. `name` (this upload's) appears only in this call's error: stored
  // models have no name, so errors about them name format and hash.
  absl::StatusOr<StoredModel> Put(ModelFormat format, std::string bytes, const std::string& name,
                                  bool* already = nullptr) ABSL_LOCKS_EXCLUDED(mu_);

  // sha256 references only; a path is INVALID_ARGUMENT (the server opens no
  // client paths), an unknown hash NOT_FOUND.
  absl::StatusOr<StoredModel> Resolve(const ModelSpec& spec) const override
      ABSL_LOCKS_EXCLUDED(mu_);

  // Called with the hash of every model evicted for the budget, outside the
  // store's lock. Set once, before the store is shared.
  void SetEvictionListener(std::function<void(const std::string& sha256)> listener) {
    on_evict_ = std::move(listener);
  }

  // Counts an upload turned away for its size (the service stops reading it
  // before Put).
  void CountRejected() ABSL_LOCKS_EXCLUDED(mu_);

  ModelStoreStats stats() const ABSL_LOCKS_EXCLUDED(mu_);
  uint64_t budget_bytes() const { return budget_bytes_; }
  uint64_t max_model_bytes() const { return max_model_bytes_; }

 private:
  // Counts `bytes` more as held by uploads, evicting stored models until
  // stored + held fit the budget; RESOURCE_EXHAUSTED (nothing counted) when
  // the uploads' bytes alone would not fit.
  absl::Status Hold(uint64_t bytes) ABSL_LOCKS_EXCLUDED(mu_);
  void Release(uint64_t bytes) ABSL_LOCKS_EXCLUDED(mu_);
  // Evicts least recently used models until stored + held fit the budget,
  // keeping at least `keep` models; returns the evicted hashes.
  std::vector<std::string> EvictForBudget(size_t keep)
      ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_);
  void NotifyEvicted(const std::vector<std::string>& evicted) const;

  // Constant after construction.
  const uint64_t budget_bytes_;
  const uint64_t max_model_bytes_;
  std::function<void(const std::string&)> on_evict_;  // set before use

  mutable absl::Mutex mu_;
  // sha256 -> model, costing its bytes; a model stored under two formats
  // keeps the first. Resolve touches it, hence mutable.
  mutable Lru<std::string, StoredModel> models_ ABSL_GUARDED_BY(mu_);
  uint64_t held_ ABSL_GUARDED_BY(mu_) = 0;  // by uploads being received
  ModelStoreStats stats_ ABSL_GUARDED_BY(mu_);  // models and bytes: see models_
};

}  // namespace sfc

#endif  // SFCSAMPLER_SERVER_MODEL_STORE_H_
