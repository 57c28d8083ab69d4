// libFuzzer target: muparser expressions as the catalogue compiles them
// (catalog/expression.h). The first 16 bytes give two evaluation points, the
// rest is the expression text over u, v, x, y, z. A compiled expression must
// evaluate to the same bits on every call (Evaluate reuses pooled parsers),
// and EvaluateConstant must accept only finite values.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>

#include "catalog/expression.h"

namespace {

[[noreturn]] void Fail(const char* what, const std::string& text) {
  std::fprintf(stderr, "fuzz: %s\n  expression: \"%s\"\n", what, text.c_str());
  __builtin_trap();
}

bool SameBits(double a, double b) {
  return std::memcmp(&a, &b, sizeof a) == 0 || (std::isnan(a) && std::isnan(b));
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 16 || size > 16 + 512) return 0;
  double a, b;
  std::memcpy(&a, data, 8);
  std::memcpy(&b, data + 8, 8);
  const std::string text(reinterpret_cast<const char*>(data) + 16, size - 16);

  auto expr = sfc::Expression::Compile("fuzz expression", text, {"u", "v", "x", "y", "z"});
  if (expr.ok()) {
    const double values[2][5] = {{a, b, a + b, a * b, 0.5}, {0.25, 0.75, -1, 2, 1e300}};
    for (const auto& point : values) {
      const double first = (*expr)->Evaluate(point);
      const double second = (*expr)->Evaluate(point);
      if (!SameBits(first, second)) Fail("two evaluations at the same point differ", text);
    }
  } else if (expr.status().code() != absl::StatusCode::kInvalidArgument ||
             expr.status().message().empty()) {
    Fail("a bad expression is not INVALID_ARGUMENT with a message", text);
  }

  auto constant = sfc::EvaluateConstant("fuzz constant", text);
  if (constant.ok() && !std::isfinite(*constant)) Fail("a non-finite constant was accepted", text);
  return 0;
}
