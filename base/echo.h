// Echoing untrusted text (file contents, upload names) into messages and
// logs: control characters and non-ASCII bytes are escaped (\n, \t, \xNN), so
// an echo can forge no log line or terminal sequence, and the echo is clipped,
// so a message stays short whatever the input's length.
//
// Thread-safety: pure functions.
#ifndef SFCSAMPLER_BASE_ECHO_H_
#define SFCSAMPLER_BASE_ECHO_H_

#include <cstddef>
#include <string>

#include "absl/strings/string_view.h"

namespace sfc {

// Longest echo of a token or line of input in a message, in characters.
inline constexpr size_t kMaxEcho = 80;
// Longest echo of an upload's name (ModelChunk.name), in characters.
inline constexpr size_t kMaxNameEcho = 128;

// `text` escaped, cut after at most `max` characters of the escaped form; a
// clipped echo ends with "... (N bytes)", N the length of `text`. The result
// has at most max + 32 bytes, all printable ASCII.
std::string Echo(absl::string_view text, size_t max = kMaxEcho);

// `text` as the value of a quoted log field (key="..."): Echo's escapes, and
// '"' as '\"', so no text, a client's or ours, can end the field early and
// forge the fields after it (code=, sent=). At most max + 32 bytes before
// the quotes' escapes.
std::string LogField(absl::string_view text, size_t max = kMaxEcho);

// `message` cut to at most `max` bytes (>= 32) at a character boundary, ending
// with " ... (message clipped)" when cut. For the wire and logs: the text is
// ours, so it is not escaped, but never longer than `max`.
std::string ClipMessage(absl::string_view message, size_t max);

}  // namespace sfc

#endif  // SFCSAMPLER_BASE_ECHO_H_
