// Model specs (FORMAT:REFERENCE) as a request names them, with no parser
// behind them: which formats exist, how a spec parses, a file's content hash
// and the routing key of everything about one model. Shared by the client,
// which uploads models, and the engine, which resolves them
// (engine/model_source.h). Thread-safe, pure functions.
#ifndef SFCSAMPLER_REQUEST_MODEL_SPEC_H_
#define SFCSAMPLER_REQUEST_MODEL_SPEC_H_

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "absl/status/statusor.h"

namespace sfc {

enum class ModelFormat { kStep, kIges, kNurbs, kObj, kPly };

std::string_view ModelFormatName(ModelFormat format);  // "step", "iges", "nurbs", "obj", "ply"
std::optional<ModelFormat> ModelFormatFromName(std::string_view name);
// Every format, in the order of ModelFormatList.
std::vector<ModelFormat> AllModelFormats();
// Every format's name, for messages: "step, iges, nurbs, obj or ply".
std::string ModelFormatList();

// SHA-256 of `bytes` as 64 lowercase hex digits.
std::string Sha256Hex(std::string_view bytes);

// The seed of a model with content hash `sha256_hex` (64 hex digits) in a
// many-model run under `base_seed` (`sfcsampler sample-many`, Python's
// sample_many): the first 8 bytes, big-endian, of
// SHA-256("sfcsampler.model-seed\0" + base_seed as 8 bytes little-endian + the
// hash's 32 bytes), top bit cleared. python/sfcsampler/many.py's model_seed()
// computes the same.
uint64_t ModelSeed(uint64_t base_seed, std::string_view sha256_hex);

// The x-surface-key (the consistent-hash proxy's routing key, docker/) of
// every request about one model: FindModel, UploadModel, and the Sample and
// Prepare that name it, so all of them reach the replica that stores it.
// "FORMAT:sha256=<hex>", the canonical spec, whatever the density or
// options (one model's trees then share a replica too). `sha256`: 64
// lowercase hex digits. The Python client (python/sfcsampler/client.py)
// makes the same string.
std::string ModelRoutingKey(ModelFormat format, std::string_view sha256);

// What a client adds to an upload that failed without the server's word:
// when `message` (gRPC's status text) shows the stream was reset or answered
// by something that does not speak gRPC (a proxy's request-body limit: nginx
// refuses bodies over client_max_body_size, 1 MiB by default, and the client
// sees "Received RST_STREAM with error code 0"), a sentence that says so and
// what to change; "" otherwise. `bytes`: the upload's size. Both clients
// (client/sampler_client.cc, python/sfcsampler/client.py) append it.
std::string UploadCutHint(std::string_view message, uint64_t bytes);

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

// A model's bytes, named by their hash. Immutable.
struct StoredModel {
  ModelFormat format = ModelFormat::kStep;
  std::string sha256;                        // of *bytes
  std::shared_ptr<const std::string> bytes;  // the file's content
  std::string name;                          // file name for messages ("" if unknown)

  // "FORMAT:sha256=<hex>", the canonical spec.
  std::string Spec() const;
};

// The largest model file the CLI and the client read, 1 GiB.
inline constexpr uint64_t kMaxModelFileBytes = uint64_t{1} << 30;

// Reads the file a path spec names (up to max_bytes) and hashes it, as the
// CLI does in process and the client before an upload. Errors: NOT_FOUND for
// a sha256 reference (only a server stores those), INVALID_ARGUMENT for an
// unreadable file, RESOURCE_EXHAUSTED past max_bytes; messages echo the path
// clipped.
absl::StatusOr<StoredModel> ReadModelFile(const ModelSpec& spec, uint64_t max_bytes);

}  // namespace sfc

#endif  // SFCSAMPLER_REQUEST_MODEL_SPEC_H_
