#include "base/echo.h"

#include <algorithm>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_replace.h"

namespace sfc {

std::string Echo(absl::string_view text, size_t max) {
  std::string out;
  out.reserve(std::min(text.size(), max) + 24);
  size_t shown = 0;
  for (; shown < text.size(); ++shown) {
    const unsigned char c = static_cast<unsigned char>(text[shown]);
    std::string piece;
    switch (c) {
      case '\n':
        piece = "\\n";
        break;
      case '\r':
        piece = "\\r";
        break;
      case '\t':
        piece = "\\t";
        break;
      case '\\':
        piece = "\\\\";
        break;
      default:
        piece = c < 0x20 || c >= 0x7f ? absl::StrFormat("\\x%02x", c) : std::string(1, c);
    }
    if (out.size() + piece.size() > max) break;
    out += piece;
  }
  if (shown < text.size()) absl::StrAppend(&out, "... (", text.size(), " bytes)");
  return out;
}

std::string LogField(absl::string_view text, size_t max) {
  return absl::StrReplaceAll(Echo(text, max), {{"\"", "\\\""}});
}

std::string ClipMessage(absl::string_view message, size_t max) {
  if (message.size() <= max) return std::string(message);
  constexpr absl::string_view kTail = " ... (message clipped)";
  size_t keep = max > kTail.size() ? max - kTail.size() : 0;
  // Do not split a UTF-8 sequence: back up over continuation bytes.
  while (keep > 0 && (static_cast<unsigned char>(message[keep]) & 0xC0) == 0x80) --keep;
  return absl::StrCat(message.substr(0, keep), kTail);
}

}  // namespace sfc
