// The flags every sampling subcommand shares (request/request_flags.h), read
// as the CLI and the Python keywords read them (issue 37): whole numbers
// outside 0..2^64-1 are refused quoting what was typed, never saturated, and
// rho must be positive before a request leaves the client. And the one rule
// for the size a request's tree is built for (request/tree_count.h).
#include "request/request_flags.h"
#include "request/tree_count.h"

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "gtest/gtest.h"

namespace sfc {
namespace {

// Parses `args` after the program name; the CLI11 error's text, or "" if
// they parse.
std::string Parse(std::vector<std::string> args, RequestFlags* flags) {
  CLI::App app;
  AddTreeFlags(&app, flags);
  AddSampleFlags(&app, flags);
  std::reverse(args.begin(), args.end());  // CLI11 takes them last first
  try {
    app.parse(args);
  } catch (const CLI::ParseError& e) {
    return e.what();
  }
  return "";
}

TEST(RequestFlags, WholeNumbersOutsideUint64AreRefusedAsTyped) {
  for (const std::string flag : {"--seed", "--count", "--tree-count", "--begin", "--end"}) {
    for (const std::string value :
         {"-1", "18446744073709551616", "99999999999999999999999", "1e3", "0x10", "", "+"}) {
      RequestFlags flags;
      const std::string error = Parse({flag, value}, &flags);
      EXPECT_NE(error.find("whole number from 0 to 18446744073709551615"), std::string::npos)
          << flag << " " << value << ": " << error;
      EXPECT_NE(error.find("'" + value + "'"), std::string::npos) << error;
    }
  }
  RequestFlags flags;
  ASSERT_EQ(Parse({"--seed", "18446744073709551615", "--count", "0"}, &flags), "");
  EXPECT_EQ(flags.seed, UINT64_MAX);
  EXPECT_EQ(flags.count, 0u);
  ASSERT_EQ(Parse({"--seed", "18446744073709551614"}, &flags), "");
  EXPECT_EQ(flags.seed, UINT64_MAX - 1);  // distinct seeds stay distinct
}

TEST(RequestFlags, RhoMustBePositiveBeforeARequestIsMade) {
  for (const std::string rho : {"0", "-1", "nan", "inf"}) {
    RequestFlags flags;
    ASSERT_EQ(Parse({"--rho", rho}, &flags), "") << rho;
    auto request = ToSampleRequest(flags);
    ASSERT_FALSE(request.ok()) << rho;
    EXPECT_EQ(request.status().code(), absl::StatusCode::kInvalidArgument);
    EXPECT_NE(request.status().message().find("--rho must be a positive number"), std::string::npos)
        << request.status();
  }
  RequestFlags flags;
  ASSERT_EQ(Parse({"--rho", "0.25"}, &flags), "");
  auto request = ToSampleRequest(flags);
  ASSERT_TRUE(request.ok()) << request.status();
  EXPECT_EQ(request->tree.options.rho, 0.25);
}

TEST(TreeCount, TheTreeHoldsTheWholeSet) {
  RequestFlags flags;
  ASSERT_EQ(Parse({"--count", "1000"}, &flags), "");
  EXPECT_EQ(*ResolveTreeCount(*ToSampleRequest(flags)), 1000u);  // 0: sized for count
  ASSERT_EQ(Parse({"--count", "1000", "--tree-count", "4096"}, &flags), "");
  EXPECT_EQ(*ResolveTreeCount(*ToSampleRequest(flags)), 4096u);
  ASSERT_EQ(Parse({"--count", "1000", "--tree-count", "999"}, &flags), "");
  auto below = ResolveTreeCount(*ToSampleRequest(flags));
  EXPECT_EQ(below.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(below.status().message().find("tree_count 999 is below count 1000"), std::string::npos);
}

}  // namespace
}  // namespace sfc
