// Core sampler benchmarks (issue: tree build + 10^6 samples on the unit
// sphere; generation from a built tree; bytes per leaf). Run one core:
//   taskset -c 0 ./build/bench/core_benchmark
#include <memory>
#include <string>

#include "benchmark/benchmark.h"
#include "catalog/catalog.h"
#include "core/builtin_surfaces.h"
#include "core/curve_tree.h"
#include "core/density.h"
#include "core/sampler.h"

namespace sfc {
namespace {

constexpr uint64_t kMillion = 1'000'000;

std::shared_ptr<const Surface> Sphere() { return std::shared_ptr<const Surface>(MakeSphere(1)); }
std::shared_ptr<const Density> Uniform() {
  return std::shared_ptr<const Density>(MakeUniformDensity());
}

// Reads every sample of the cursor in batches of `batch_size` (64 Ki, as the
// server's streams; the Python package's sample() asks for all at once);
// returns the count.
uint64_t Drain(SampleCursor& cursor, SampleBatch& batch, size_t batch_size = 65536) {
  uint64_t total = 0;
  while (true) {
    batch.Clear();
    const size_t n = *cursor.Next(batch_size, &batch);
    if (n == 0) return total;
    total += n;
  }
}

// The timed loop of generation alone: n jittered samples (seed 1) from a tree
// built once for `surface` (uniform density), drained on `threads` threads.
void SampleFromBuiltTree(benchmark::State& state, std::shared_ptr<const Surface> surface,
                         const CurveTreeOptions& options, uint64_t n, int threads = 1,
                         size_t batch_size = 65536) {
  auto density = Uniform();
  auto tree = *CurveTree::Build(*surface, *density, options, CurveTree::GradeFor(n));
  auto sampler = std::make_shared<const Sampler>(tree, surface, density,
                                                 Sequence(SequenceKind::kJittered, n, 1));
  SampleBatch batch;
  for (auto _ : state) {
    auto cursor = *SampleCursor::Create(sampler, 0, n, {}, {}, threads);
    benchmark::DoNotOptimize(Drain(*cursor, batch, batch_size));
  }
  state.SetItemsProcessed(state.iterations() * n);
}

void BM_BuildTreeAndSampleSphere(benchmark::State& state) {
  const uint64_t n = state.range(0);
  CurveTreeOptions options;
  options.rho = static_cast<double>(state.range(1));
  auto surface = Sphere();
  auto density = Uniform();
  SampleBatch batch;
  size_t leaves = 0;
  for (auto _ : state) {
    auto tree = *CurveTree::Build(*surface, *density, options, CurveTree::GradeFor(n));
    leaves = tree->leaf_count();
    auto sampler = std::make_shared<const Sampler>(tree, surface, density,
                                                   Sequence(SequenceKind::kJittered, n, 1));
    auto cursor = *SampleCursor::Create(sampler, 0, n, {}, {});
    benchmark::DoNotOptimize(Drain(*cursor, batch));
  }
  state.counters["leaves"] = static_cast<double>(leaves);
  state.SetItemsProcessed(state.iterations() * n);
}
// Second argument: rho (1 is the default; it scales the tree's model-error
// allowance, larger trades accuracy for a coarser tree).
BENCHMARK(BM_BuildTreeAndSampleSphere)
    ->Args({kMillion, 1})
    ->Args({kMillion, 4})
    ->Unit(benchmark::kMillisecond);

void BM_BuildTreeOnlySphere(benchmark::State& state) {
  const uint64_t n = state.range(0);
  auto surface = Sphere();
  auto density = Uniform();
  for (auto _ : state) {
    benchmark::DoNotOptimize(*CurveTree::Build(*surface, *density, {}, CurveTree::GradeFor(n)));
  }
}
BENCHMARK(BM_BuildTreeOnlySphere)->Arg(kMillion)->Unit(benchmark::kMillisecond);

// Generation alone: 10^6 samples with surface evaluation from a built tree.
void BM_SampleFromBuiltTree(benchmark::State& state) {
  const uint64_t n = kMillion;
  const auto curve = static_cast<CurveType>(state.range(0));
  auto surface = state.range(1) ? std::shared_ptr<const Surface>(MakePlane()) : Sphere();
  CurveTreeOptions options;
  options.curve = curve;
  SampleFromBuiltTree(state, surface, options, n);
  state.SetLabel(std::string(CurveName(curve)) + (state.range(1) ? " plane" : " sphere"));
}
BENCHMARK(BM_SampleFromBuiltTree)
    ->Args({static_cast<int>(CurveType::kHilbert), 0})
    ->Args({static_cast<int>(CurveType::kHilbert), 1})
    ->Args({static_cast<int>(CurveType::kHilbert2), 0})
    ->Unit(benchmark::kMillisecond);

// Per-sample cost from a built tree on several surfaces (uniform density,
// Hilbert, one thread), at N = 10^6 and just above a power of two, N = 2^23 + 1
// (a tree of grade 2^24: tables sized for twice the samples). First argument:
// the surface, kSpecSurfaces[i]; second: N.
constexpr const char* kSpecSurfaces[] = {"sphere", "torus", "superellipsoid",
                                         "expr:x=u;y=v;z=0.3*sin(6*u)*cos(4*v)"};
void BM_SampleSurface(benchmark::State& state) {
  const char* spec = kSpecSurfaces[state.range(0)];
  const uint64_t n = static_cast<uint64_t>(state.range(1));
  SampleFromBuiltTree(state, MakeSurface(spec)->surface, {}, n);
  state.SetLabel(spec);
}
BENCHMARK(BM_SampleSurface)
    ->ArgsProduct({{0, 1, 2, 3}, {kMillion, (1 << 23) + 1}})
    ->Unit(benchmark::kMillisecond);

// 4 M sphere samples in one batch, as the Python package's sample() asks for
// them (its row of issue 34's table), into a batch whose columns are kept.
void BM_SampleSphereInOneBatch(benchmark::State& state) {
  const uint64_t n = 4'000'000;
  SampleFromBuiltTree(state, Sphere(), {}, n, 1, n);
  state.SetLabel("sphere, 4 M in one batch");
}
BENCHMARK(BM_SampleSphereInOneBatch)->Unit(benchmark::kMillisecond);

// The same generation on `threads` threads of the shared pool (wall time):
// batches of 64 Ki split into contiguous parts, the same bytes as one thread.
void BM_SampleFromBuiltTreeThreads(benchmark::State& state) {
  const uint64_t n = kMillion;
  const int threads = static_cast<int>(state.range(0));
  SampleFromBuiltTree(state, Sphere(), {}, n, threads);
  state.SetLabel("hilbert sphere, " + std::to_string(threads) + " threads");
}
BENCHMARK(BM_SampleFromBuiltTreeThreads)
    ->Arg(1)
    ->Arg(2)
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);

// Bytes per leaf, measured from the tree's own arrays.
void BM_BytesPerLeaf(benchmark::State& state) {
  auto surface = Sphere();
  auto density = Uniform();
  std::shared_ptr<const CurveTree> tree;
  for (auto _ : state)
    tree = *CurveTree::Build(*surface, *density, {}, CurveTree::GradeFor(kMillion));
  state.counters["bytes_per_leaf"] = static_cast<double>(tree->bytes()) / tree->leaf_count();
  state.counters["leaves"] = static_cast<double>(tree->leaf_count());
}
BENCHMARK(BM_BytesPerLeaf)->Iterations(1)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace sfc

BENCHMARK_MAIN();
