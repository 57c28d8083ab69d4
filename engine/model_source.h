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

namespace sfc {

enum class ModelFormat { kStep, kIges, kNurbs, kObj, kPly };

std::string_view ModelFormatName(ModelFormat format);  // "step", "iges", "nurbs", "obj", "ply"
std::optional<ModelFormat> ModelFormatFromName(std::string_view name);

// SHA-256 of `bytes` as 64 lowercase hex digits.
std::string Sha256Hex(std::string_view bytes);

struct StoredModel {
  ModelFormat format = ModelFormat::kStep;
  std::string sha256;                        // of *bytes
  std::shared_ptr<const std::string> bytes;  // the file's content
  std::string name;                          // file name for messages ("" if unknown)

  // "FORMAT:sha256=<hex>", the canonical spec.
  std::string Spec() const;
};

// The x-surface-key (the consistent-hash proxy's routing key, docker/) of
// every request about one model: FindModel, UploadModel, and the Sample and
// Prepare that name it, so all of them reach the replica that stores it.
// "FORMAT:sha256=<hex>", the canonical spec, whatever the density or
// options (one model's trees then share a replica too). `sha256`: 64
// lowercase hex digits. The Python client (python/sfcsampler/client.py)
// makes the same string.
std::string ModelRoutingKey(ModelFormat format, std::string_view sha256);

// A parsed model spec: the format and the reference after the colon.
struct ModelSpec {
  ModelFormat format;
  std::string reference;  // a path, or "sha256=<hex>"
  // The hash when the reference is "sha256=<hex>" (validated), else "".
  std::string sha256;
};
// nullopt when `spec` does not start with a model format name and a colon
// (it is then a catalogue surface); INVALID_ARGUMENT for a malformed
// sha256 reference or an empty one.
absl::StatusOr<std::optional<ModelSpec>> ParseModelSpec(std::string_view spec);

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
  explicit FileModelSource(uint64_t max_bytes = uint64_t{1} << 30) : max_bytes_(max_bytes) {}
  absl::StatusOr<StoredModel> Resolve(const ModelSpec& spec) const override;

 private:
  const uint64_t max_bytes_;
};

}  // namespace sfc

#endif  // SFCSAMPLER_ENGINE_MODEL_SOURCE_H_
