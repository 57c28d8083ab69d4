// libFuzzer target: surface and density specs (catalog/catalog.h), built-in
// and `expr:` ones. The first byte picks surface or density; the rest is the
// spec. An accepted spec must evaluate without crashing anywhere in the unit
// square, and its canonical form must be a fixed point: parsing it again is
// accepted and gives the same canonical text (cache keys rely on it).
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>

#include "catalog/catalog.h"

namespace {

[[noreturn]] void Fail(const char* what, const std::string& spec, const std::string& detail) {
  std::fprintf(stderr, "fuzz: %s\n  spec: \"%s\"\n  %s\n", what, spec.c_str(), detail.c_str());
  __builtin_trap();
}

constexpr double kProbes[] = {0, 0.25, 0.5, 1};

void CheckSurface(const std::string& spec) {
  auto made = sfc::MakeSurface(spec);
  if (!made.ok()) {
    if (made.status().code() != absl::StatusCode::kInvalidArgument) {
      Fail("a bad surface spec is not INVALID_ARGUMENT", spec, made.status().ToString());
    }
    return;
  }
  for (double u : kProbes) {
    for (double v : kProbes) {
      (void)made->surface->Point(u, v);
      (void)sfc::GeometryOf(made->surface->Jet(u, v, 2));
    }
  }
  auto again = sfc::MakeSurface(made->canonical);
  if (!again.ok()) Fail("the canonical surface spec is rejected", spec, made->canonical);
  if (again->canonical != made->canonical) {
    Fail("the canonical surface spec is not a fixed point", spec,
         made->canonical + " -> " + again->canonical);
  }
}

void CheckDensity(const std::string& spec) {
  auto made = sfc::MakeDensity(spec);
  if (!made.ok()) {
    if (made.status().code() != absl::StatusCode::kInvalidArgument) {
      Fail("a bad density spec is not INVALID_ARGUMENT", spec, made.status().ToString());
    }
    return;
  }
  sfc::SurfacePoint p{};
  for (double u : kProbes) {
    p.u = u;
    p.v = 1 - u;
    p.p = {u, 2 * u, -u};
    (void)made->density->Value(p);
  }
  auto again = sfc::MakeDensity(made->canonical);
  if (!again.ok()) Fail("the canonical density spec is rejected", spec, made->canonical);
  if (again->canonical != made->canonical) {
    Fail("the canonical density spec is not a fixed point", spec,
         made->canonical + " -> " + again->canonical);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0 || size > 1024) return 0;
  const std::string spec(reinterpret_cast<const char*>(data) + 1, size - 1);
  if (data[0] & 1) {
    CheckDensity(spec);
  } else {
    CheckSurface(spec);
  }
  return 0;
}
