// base/echo.h: escaped, bounded echoes of untrusted text.
#include "base/echo.h"

#include <string>

#include "gtest/gtest.h"

namespace sfc {
namespace {

bool Printable(const std::string& s) {
  for (char c : s) {
    if (c < 0x20 || c > 0x7e) return false;
  }
  return true;
}

TEST(Echo, EscapesControlAndNonAsciiBytesAndBoundsTheResult) {
  EXPECT_EQ(Echo("part.step"), "part.step");
  EXPECT_EQ(Echo("a\nb\tc\\d\x01\xff"), "a\\nb\\tc\\\\d\\x01\\xff");
  for (const std::string& input : {std::string(1 << 20, '\x85'), std::string(1 << 20, 'x'),
                                   std::string(1 << 20, '\n')}) {
    const std::string echo = Echo(input);
    EXPECT_LE(echo.size(), kMaxEcho + 32) << echo;
    EXPECT_TRUE(Printable(echo)) << echo;
    EXPECT_NE(echo.find("(1048576 bytes)"), std::string::npos) << echo;
  }
  // An escape is never cut in half.
  const std::string cut = Echo(std::string(100, '\x85'), 10);
  EXPECT_EQ(cut.substr(0, 8), "\\x85\\x85");
  EXPECT_EQ(cut.substr(8, 3), "...");
}

TEST(Echo, ClipMessageKeepsShortMessagesAndCutsLongOnesAtACharacter) {
  EXPECT_EQ(ClipMessage("short", 1024), "short");
  const std::string clipped = ClipMessage(std::string(5000, 'y'), 1024);
  EXPECT_LE(clipped.size(), 1024u);
  EXPECT_NE(clipped.find("(message clipped)"), std::string::npos);
  std::string utf8;
  for (int i = 0; i < 1000; ++i) utf8 += "\xc3\xa9";  // é
  const std::string cut = ClipMessage(utf8, 101);
  EXPECT_LE(cut.size(), 101u);
  const size_t body = cut.find(" ... ");
  EXPECT_EQ(body % 2, 0u) << "a UTF-8 sequence was split";
}

// Issue 37: a quoted log field cannot be ended early by the text inside it.
TEST(Echo, LogFieldEscapesQuotesSoNoFieldCanBeForged) {
  const std::string forged = "expr:1\" code=0 sent=1000 msg=\"";
  const std::string field = LogField(forged);
  EXPECT_EQ(field, "expr:1\\\" code=0 sent=1000 msg=\\\"");
  // Read back as a log reader would: the field ends at the first quote not
  // behind a backslash, which is the end of the field.
  const std::string line = "surface=\"" + field + "\" code=3";
  size_t end = line.find('"') + 1;
  while (line[end] != '"') end += line[end] == '\\' ? 2 : 1;
  EXPECT_EQ(line.substr(end), "\" code=3");
  EXPECT_EQ(LogField("a\\\"b"), "a\\\\\\\"b");  // a backslash before a quote stays unambiguous
  EXPECT_LE(LogField(std::string(10000, '"'), 100).size(), 2 * 100 + 32u);
}

}  // namespace
}  // namespace sfc
