// Prints docs/MEASURED.md's tree table: leaves, bytes and build time of the default
// tree (jittered Hilbert, default options and budget) for the sphere, the
// torus, the eight surface with |K| density and the superellipsoid with
// exponent 1/3 (no reparameterisation), at N = 10^4, 10^6 and 10^8, with the
// precision report (singular leaves, estimated model error in samples).
// Each build is from scratch and timed once (wall clock, one thread).
//   build/bench/tree_benchmark [max_leaves]
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "catalog/catalog.h"
#include "core/curve_tree.h"

int main(int argc, char** argv) {
  using sfc::CurveTree;
  sfc::CurveTreeOptions options;  // the defaults, budget 2^22 leaves
  if (argc > 1) options.max_leaves = std::strtoull(argv[1], nullptr, 10);
  struct Case {
    const char* surface;
    const char* density;
  };
  const Case cases[] = {{"sphere", "uniform"},
                        {"torus", "uniform"},
                        {"eight", "gaussian:floor=0.05"},
                        {"superellipsoid", "uniform"}};
  std::printf(
      "| surface, density | N | leaves | bytes | build | depth | singular leaves | model error "
      "(samples) |\n");
  std::printf("|---|---:|---:|---:|---:|---:|---:|---:|\n");
  for (const Case& c : cases) {
    auto surface = sfc::MakeSurface(c.surface);
    auto density = sfc::MakeDensity(c.density);
    if (!surface.ok() || !density.ok()) return 1;
    for (uint64_t n : {uint64_t{10'000}, uint64_t{1'000'000}, uint64_t{100'000'000}}) {
      const auto start = std::chrono::steady_clock::now();
      auto tree =
          CurveTree::Build(*surface->surface, *density->density, options, CurveTree::GradeFor(n));
      const double seconds =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      if (!tree.ok()) {
        std::printf("| %s, %s | %llu | %s | | | | | |\n", c.surface, c.density,
                    static_cast<unsigned long long>(n),
                    std::string(tree.status().message()).c_str());
        continue;
      }
      const CurveTree& t = **tree;
      std::printf("| %s, %s | %llu | %zu | %.1f MB | %.3f s | %d..%d | %llu | %.2g |\n", c.surface,
                  c.density, static_cast<unsigned long long>(n), t.leaf_count(), t.bytes() / 1e6,
                  seconds, t.min_depth(), t.max_depth(),
                  static_cast<unsigned long long>(t.precision().singular_leaves),
                  t.precision().error_samples);
      std::fflush(stdout);
    }
  }
  return 0;
}
