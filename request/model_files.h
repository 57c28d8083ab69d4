// Model files as the CLI and Python find and read them: the file-name
// extensions of each model format and the default CPU budget of one model's
// read. The one copy of these facts: the CLI (client/cli/sample_many.cc,
// client/cli/model_read_flags.h) uses them, and Python's many-model runs
// (python/sfcsampler/many.py) get them from the extension module
// (_core.MODEL_EXTENSIONS, _core.MODEL_PARSE_SECONDS). Thread-safe, pure.
#ifndef SFCSAMPLER_REQUEST_MODEL_FILES_H_
#define SFCSAMPLER_REQUEST_MODEL_FILES_H_

#include <optional>
#include <string>
#include <string_view>

#include "absl/types/span.h"
#include "request/model_spec.h"

namespace sfc {

struct ModelExtension {
  std::string_view extension;  // lower case, with the dot: ".step"
  ModelFormat format;
};

// Every extension a model file may have, in the order messages list them:
// .step .stp .iges .igs .nurbs .obj .ply.
absl::Span<const ModelExtension> ModelExtensions();

// The format of a file by its name's extension (std::filesystem's, compared
// without case: "PART.STP" is STEP); nullopt for any other extension.
std::optional<ModelFormat> ModelFormatOfPath(std::string_view path);

// The extensions separated by spaces, for messages:
// ".step .stp .iges .igs .nurbs .obj .ply".
std::string ModelExtensionList();

// CPU seconds one model's read may take unless told otherwise: the CLI's
// --model-parse-seconds and Python's sfcsampler.many (a CAD file's check
// program is stopped at this limit).
inline constexpr double kDefaultModelParseSeconds = 300;

}  // namespace sfc

#endif  // SFCSAMPLER_REQUEST_MODEL_FILES_H_
