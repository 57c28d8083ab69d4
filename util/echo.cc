#include "util/echo.h"

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"

namespace sfc {

std::string Echo(absl::string_view text, size_t max) {
  std::string out;
  const absl::string_view shown = text.substr(0, max);
  out.reserve(shown.size() + 16);
  for (const char ch : shown) {
    const unsigned char c = static_cast<unsigned char>(ch);
    switch (c) {
      case '\n':
        out += "\\n";
        break;
      case '\r':
        out += "\\r";
        break;
      case '\t':
        out += "\\t";
        break;
      case '\\':
        out += "\\\\";
        break;
      default:
        if (c < 0x20 || c >= 0x7f) {
          absl::StrAppendFormat(&out, "\\x%02x", c);
        } else {
          out += ch;
        }
    }
  }
  if (shown.size() < text.size()) absl::StrAppend(&out, "... (", text.size(), " bytes)");
  return out;
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
