#include "request/model_spec.h"

#include <openssl/sha.h>

#include <array>
#include <filesystem>
#include <fstream>

#include "absl/strings/ascii.h"
#include "absl/strings/escaping.h"
#include "absl/strings/match.h"
#include "absl/strings/str_format.h"
#include "absl/strings/strip.h"
#include "base/echo.h"

namespace sfc {
namespace {

constexpr std::array<std::pair<ModelFormat, std::string_view>, 5> kFormats = {{
    {ModelFormat::kStep, "step"},
    {ModelFormat::kIges, "iges"},
    {ModelFormat::kNurbs, "nurbs"},
    {ModelFormat::kObj, "obj"},
    {ModelFormat::kPly, "ply"},
}};

}  // namespace

std::string_view ModelFormatName(ModelFormat format) {
  for (const auto& [f, name] : kFormats) {
    if (f == format) return name;
  }
  return "unknown";
}

std::optional<ModelFormat> ModelFormatFromName(std::string_view name) {
  for (const auto& [f, n] : kFormats) {
    if (n == name) return f;
  }
  return std::nullopt;
}

std::vector<ModelFormat> AllModelFormats() {
  std::vector<ModelFormat> out;
  for (const auto& [format, name] : kFormats) out.push_back(format);
  return out;
}

std::string ModelFormatList() {
  std::string out;
  for (size_t i = 0; i < kFormats.size(); ++i) {
    if (i > 0) out += i + 1 == kFormats.size() ? " or " : ", ";
    out += kFormats[i].second;
  }
  return out;
}

std::string Sha256Hex(std::string_view bytes) {
  unsigned char digest[SHA256_DIGEST_LENGTH];
  SHA256(reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size(), digest);
  std::string hex;
  hex.reserve(2 * SHA256_DIGEST_LENGTH);
  for (unsigned char c : digest) absl::StrAppendFormat(&hex, "%02x", c);
  return hex;
}

uint64_t ModelSeed(uint64_t base_seed, std::string_view sha256_hex) {
  std::string message("sfcsampler.model-seed", 21);
  message.push_back('\0');
  for (int i = 0; i < 8; ++i) message.push_back(static_cast<char>((base_seed >> (8 * i)) & 0xff));
  message += absl::HexStringToBytes(absl::string_view(sha256_hex.data(), sha256_hex.size()));
  unsigned char digest[SHA256_DIGEST_LENGTH];
  SHA256(reinterpret_cast<const unsigned char*>(message.data()), message.size(), digest);
  uint64_t seed = 0;
  for (int i = 0; i < 8; ++i) seed = (seed << 8) | digest[i];
  return seed & ((uint64_t{1} << 63) - 1);
}

std::string ModelRoutingKey(ModelFormat format, std::string_view sha256) {
  return absl::StrFormat("%s:sha256=%s", ModelFormatName(format), sha256);
}

absl::StatusOr<std::optional<ModelSpec>> ParseModelSpec(std::string_view text) {
  // Bookworm's Abseil has its own string_view.
  const absl::string_view spec =
      absl::StripAsciiWhitespace(absl::string_view(text.data(), text.size()));
  const size_t colon = spec.find(':');
  if (colon == absl::string_view::npos) return std::nullopt;
  const auto format = ModelFormatFromName(std::string_view(spec.data(), colon));
  if (!format) return std::nullopt;
  ModelSpec out{*format, std::string(absl::StripAsciiWhitespace(spec.substr(colon + 1))), ""};
  if (out.reference.empty()) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "the model spec \"%s\" names no file; write %s:FILE (or %s:sha256=HASH for a model "
        "uploaded to a server)",
        Echo(spec), ModelFormatName(*format), ModelFormatName(*format)));
  }
  if (absl::StartsWith(out.reference, "sha256=")) {
    const std::string hash = absl::AsciiStrToLower(out.reference.substr(7));
    const bool hex =
        hash.size() == 64 && hash.find_first_not_of("0123456789abcdef") == std::string::npos;
    if (!hex) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "\"%s\" is not a SHA-256: it needs 64 hex digits after sha256=", Echo(out.reference)));
    }
    out.sha256 = hash;
    out.reference = "sha256=" + hash;
  }
  return std::optional<ModelSpec>(std::move(out));
}

std::string StoredModel::Spec() const { return ModelRoutingKey(format, sha256); }

absl::StatusOr<StoredModel> ReadModelFile(const ModelSpec& spec, uint64_t max_bytes) {
  if (!spec.sha256.empty()) {
    return absl::NotFoundError(absl::StrFormat(
        "%s names an uploaded model, which only a server stores; give the file's path instead, "
        "or add --server",
        Echo(spec.reference)));
  }
  std::error_code error;
  const auto size = std::filesystem::file_size(spec.reference, error);
  if (error) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "cannot read the model \"%s\": %s", Echo(spec.reference, kMaxNameEcho), error.message()));
  }
  if (size > max_bytes) {
    return absl::ResourceExhaustedError(
        absl::StrFormat("the model \"%s\" is %d bytes, more than the limit of %d",
                        Echo(spec.reference, kMaxNameEcho), size, max_bytes));
  }
  std::ifstream in(spec.reference, std::ios::binary);
  auto bytes = std::make_shared<std::string>(size, '\0');
  if (!in || !in.read(bytes->data(), static_cast<std::streamsize>(size))) {
    return absl::InvalidArgumentError(
        absl::StrFormat("cannot read the model \"%s\"", Echo(spec.reference, kMaxNameEcho)));
  }
  StoredModel model;
  model.format = spec.format;
  model.sha256 = Sha256Hex(*bytes);
  model.bytes = std::move(bytes);
  model.name = std::filesystem::path(spec.reference).filename().string();
  return model;
}

std::string UploadCutHint(std::string_view message, uint64_t bytes) {
  const bool cut = message.find("RST_STREAM") != std::string_view::npos ||
                   message.find("http2 header with status") != std::string_view::npos ||
                   message.find("content-type") != std::string_view::npos;
  if (!cut) return "";
  return absl::StrFormat(
      " (the upload of %d bytes was cut off before the server answered: a proxy between this "
      "client and the server may refuse large request bodies; nginx does above "
      "client_max_body_size, 1 MiB by default: set it to 0 there, as docker/nginx.conf.template "
      "does, so that the server's own model size limit applies)",
      bytes);
}

}  // namespace sfc
