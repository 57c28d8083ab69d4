#include "request/stream_options.h"

#include "absl/status/status.h"
#include "absl/strings/str_format.h"
#include "absl/strings/string_view.h"
#include "base/echo.h"

namespace sfc {

absl::StatusOr<ColumnPrecision> ParseColumnPrecision(std::string_view name) {
  if (name == "float64") return ColumnPrecision::kFloat64;
  if (name == "float32") return ColumnPrecision::kFloat32;
  return absl::InvalidArgumentError(
      absl::StrFormat("precision must be float64 or float32, not \"%s\"",
                      Echo(absl::string_view(name.data(), name.size()))));
}

absl::StatusOr<ColumnEncoding> ParseColumnEncoding(std::string_view name) {
  if (name == "raw") return ColumnEncoding::kRaw;
  if (name == "packed") return ColumnEncoding::kPacked;
  return absl::InvalidArgumentError(
      absl::StrFormat("encoding must be raw or packed, not \"%s\"",
                      Echo(absl::string_view(name.data(), name.size()))));
}

}  // namespace sfc
