// User expressions against the built-in closed forms, measured side by side
// in one run, and box-region requests against the full set. Prints a table.
//
// Each row is cold: the surface is made from its spec, the tree built and all
// samples of the set (or of the region) read, as a first request does. The
// time is the median of `repeats` runs, the two columns run alternately. Run it on one core:
//   taskset -c 0 ./build/bench/expression_benchmark [N] [repeats]
// (defaults N = 1000000, repeats = 3).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "catalog/catalog.h"
#include "core/sampler.h"

namespace sfc {
namespace {

constexpr char kExprSphere[] =
    "expr:x=sin(_pi*u)*cos(2*_pi*v);y=sin(_pi*u)*sin(2*_pi*v);z=cos(_pi*u)";

struct Timing {
  double seconds = 0;
  uint64_t samples = 0;
};

// Builds the tree for `surface` x `density` and reads the samples of
// [0, n) in `region`; returns the wall time and the sample count.
Timing Cold(const std::string& surface, const std::string& density, uint64_t n,
            const Region& region, const SampleFields& fields) {
  const auto start = std::chrono::steady_clock::now();
  auto sf = MakeSurface(surface);
  auto df = MakeDensity(density);
  if (!sf.ok() || !df.ok()) {
    std::fprintf(stderr, "bad spec: %s %s\n", std::string(sf.status().message()).c_str(),
                 std::string(df.status().message()).c_str());
    std::exit(1);
  }
  auto tree = CurveTree::Build(*sf->surface, *df->density, {}, CurveTree::GradeFor(n));
  if (!tree.ok()) {
    std::fprintf(stderr, "%s\n", std::string(tree.status().message()).c_str());
    std::exit(1);
  }
  auto sampler = std::make_shared<const Sampler>(*tree, sf->surface, df->density,
                                                 Sequence(SequenceKind::kJittered, n, 1));
  auto cursor = SampleCursor::Create(sampler, 0, n, region, fields);
  if (!cursor.ok()) {
    std::fprintf(stderr, "%s\n", std::string(cursor.status().message()).c_str());
    std::exit(1);
  }
  Timing t;
  SampleBatch batch;
  while (true) {
    batch.Clear();
    auto got = (*cursor)->Next(65536, &batch);
    if (!got.ok()) {
      std::fprintf(stderr, "%s\n", std::string(got.status().message()).c_str());
      std::exit(1);
    }
    if (*got == 0) break;
    t.samples += *got;
  }
  t.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return t;
}

double MedianOf(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

int Run(uint64_t n, int repeats) {
  std::printf("%llu samples, cold (surface + tree + sampling), median of %d runs\n\n",
              static_cast<unsigned long long>(n), repeats);
  std::printf("%-34s %12s %12s %8s\n", "case", "built-in s", "expr: s", "ratio");
  SampleFields normals;
  normals.normal = true;
  SampleFields with_density;
  with_density.normal = with_density.density = true;
  struct Row {
    const char* name;
    const char* density;
    SampleFields fields;
  };
  const Row rows[] = {
      {"sphere, points", "uniform", {}},
      {"sphere, points + normals", "uniform", normals},
      {"sphere, gaussian density (order 2)", "gaussian:floor=0.1", with_density},
  };
  for (const Row& row : rows) {
    // Alternate the two so that both see the same load on a shared machine.
    std::vector<double> b, e;
    for (int i = 0; i < repeats; ++i) {
      b.push_back(Cold("sphere", row.density, n, {}, row.fields).seconds);
      e.push_back(Cold(kExprSphere, row.density, n, {}, row.fields).seconds);
    }
    const double mb = MedianOf(b), me = MedianOf(e);
    std::printf("%-34s %12.3f %12.3f %8.2f\n", row.name, mb, me, me / mb);
  }

  // Box regions on z = sin(8 pi u), from one built tree: the planner skips
  // cells on proof, so a small box costs its samples plus its boundary cells.
  const char* kWave = "expr:x=u;y=v;z=sin(8*_pi*u)";
  auto sf = MakeSurface(kWave);
  auto df = MakeDensity("uniform");
  const auto build_start = std::chrono::steady_clock::now();
  auto tree = *CurveTree::Build(*sf->surface, *df->density, {}, CurveTree::GradeFor(n));
  std::printf("\n%s: tree built in %.3f s, %zu leaves; region requests from it\n", kWave,
              std::chrono::duration<double>(std::chrono::steady_clock::now() - build_start).count(),
              tree->leaf_count());
  auto sampler = std::make_shared<const Sampler>(tree, sf->surface, df->density,
                                                 Sequence(SequenceKind::kJittered, n, 1));
  std::printf("%-34s %12s %12s\n", "region", "samples", "s");
  struct Box {
    const char* name;
    Region region;
  };
  const Box boxes[] = {
      {"all", Region{}},
      {"box z >= 0.8", Region::Box({0, 0, 0.8}, {1, 1, 1})},
      {"box z >= 0.999", Region::Box({0, 0, 0.999}, {1, 1, 1})},
      {"box 0.1 x 0.1 x all z", Region::Box({0.45, 0.45, -1}, {0.55, 0.55, 1})},
      {"box 0.01 x 0.01 x all z", Region::Box({0.495, 0.495, -1}, {0.505, 0.505, 1})},
  };
  for (const Box& box : boxes) {
    std::vector<double> seconds;
    uint64_t samples = 0;
    for (int i = 0; i < repeats; ++i) {
      const auto start = std::chrono::steady_clock::now();
      auto cursor = *SampleCursor::Create(sampler, 0, n, box.region, {});
      SampleBatch batch;
      samples = 0;
      while (true) {
        batch.Clear();
        const size_t got = *cursor->Next(65536, &batch);
        if (got == 0) break;
        samples += got;
      }
      seconds.push_back(
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    }
    std::printf("%-34s %12llu %12.4f\n", box.name, static_cast<unsigned long long>(samples),
                MedianOf(seconds));
  }
  return 0;
}

}  // namespace
}  // namespace sfc

int main(int argc, char** argv) {
  const uint64_t n = argc > 1 ? std::strtoull(argv[1], nullptr, 10) : 1000000;
  const int repeats = argc > 2 ? std::atoi(argv[2]) : 3;
  return sfc::Run(n, std::max(1, repeats));
}
