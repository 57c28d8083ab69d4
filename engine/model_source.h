// Model files (CAD and meshes) that surfaces are made from, and where their
// bytes come from (docs/SERVICE.md: "A CAD or mesh user sends a STEP, IGES, OBJ or
// PLY model once; the server keys it by a content hash").
//
// A model spec is FORMAT:REFERENCE. The reference is a file path, which only
// the embedded CLI may open (FileModelSource), or "sha256=<64 hex digits>", the
// SHA-256 of the file's bytes, which names an uploaded model on a server (its
// ModelStore). Either way the canonical spec, and so the tree key, is
// FORMAT:sha256=<hex>: the same bytes give the same trees and samples in
// process and over the wire.
//
// Thread-safety: implementations are thread-safe; StoredModel is immutable.
#ifndef SFCSAMPLER_ENGINE_MODEL_SOURCE_H_
#define SFCSAMPLER_ENGINE_MODEL_SOURCE_H_

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "absl/status/statusor.h"
#include "request/model_spec.h"

namespace sfc {


class ModelSource {
 public:
  virtual ~ModelSource() = default;
  // The model `spec` names. Errors say what to fix (unreadable file, unknown
  // hash, a path sent to a server).
  virtual absl::StatusOr<StoredModel> Resolve(const ModelSpec& spec) const = 0;
};

// For the embedded CLI: reads paths (up to max_bytes) and hashes them; a
// sha256 reference is NOT_FOUND (there is no store in process).
class FileModelSource final : public ModelSource {
 public:
  explicit FileModelSource(uint64_t max_bytes = kMaxModelFileBytes) : max_bytes_(max_bytes) {}
  absl::StatusOr<StoredModel> Resolve(const ModelSpec& spec) const override;

 private:
  const uint64_t max_bytes_;
};

}  // namespace sfc

#endif  // SFCSAMPLER_ENGINE_MODEL_SOURCE_H_
