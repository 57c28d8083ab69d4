#include "request/model_files.h"

#include <array>
#include <filesystem>

#include "absl/strings/ascii.h"
#include "absl/strings/str_join.h"

namespace sfc {
namespace {

constexpr std::array<ModelExtension, 7> kExtensions = {{
    {".step", ModelFormat::kStep},
    {".stp", ModelFormat::kStep},
    {".iges", ModelFormat::kIges},
    {".igs", ModelFormat::kIges},
    {".nurbs", ModelFormat::kNurbs},
    {".obj", ModelFormat::kObj},
    {".ply", ModelFormat::kPly},
}};

}  // namespace

absl::Span<const ModelExtension> ModelExtensions() { return kExtensions; }

std::optional<ModelFormat> ModelFormatOfPath(std::string_view path) {
  const std::string ext =
      absl::AsciiStrToLower(std::filesystem::path(std::string(path)).extension().string());
  for (const ModelExtension& e : kExtensions) {
    if (e.extension == ext) return e.format;
  }
  return std::nullopt;
}

std::string ModelExtensionList() {
  return absl::StrJoin(kExtensions, " ",
                       [](std::string* out, const ModelExtension& e) { out->append(e.extension); });
}

}  // namespace sfc
