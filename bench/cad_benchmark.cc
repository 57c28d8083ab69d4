// Costs of the CAD layer (cad/), next to the built-in sphere: loading the
// fixtures, order-2 jets of a face (the tree build's inner loop), point and
// cell classification of a trimmed face. Google Benchmark; run pinned:
//   taskset -c 0 ./build/bench/cad_benchmark
#include <memory>
#include <random>
#include <string>

#include "benchmark/benchmark.h"
#include "cad/fixtures.h"
#include "cad/load.h"
#include "cad/model.h"
#include "core/builtin_surfaces.h"

namespace {

using sfc::ModelFormat;
using sfc::cad::fixtures::Solid;

const std::string& FixtureBytes(Solid solid) {
  static const std::string sphere =
      *sfc::cad::fixtures::SolidBytes(Solid::kSphere, ModelFormat::kStep);
  static const std::string box =
      *sfc::cad::fixtures::SolidBytes(Solid::kBoxWithHole, ModelFormat::kStep);
  return solid == Solid::kSphere ? sphere : box;
}

std::shared_ptr<const sfc::cad::Model> Loaded(Solid solid) {
  return *sfc::cad::Load(ModelFormat::kStep, FixtureBytes(solid), "bench");
}

// The face of the box whose trim is the hole plus the fillet (a trimmed plane).
const sfc::cad::Face& TrimmedFace(const sfc::cad::Model& model) {
  for (const sfc::cad::Face& face : model.faces()) {
    if (face.trimmed()) return face;
  }
  return model.faces()[0];
}

void BM_Load(benchmark::State& state) {
  const Solid solid = static_cast<Solid>(state.range(0));
  const std::string& bytes = FixtureBytes(solid);
  for (auto _ : state) {
    benchmark::DoNotOptimize(sfc::cad::Load(ModelFormat::kStep, bytes, "bench"));
  }
  state.SetLabel(sfc::cad::fixtures::SolidName(solid) + ".step, " + std::to_string(bytes.size()) +
                 " bytes");
}
BENCHMARK(BM_Load)
    ->Arg(static_cast<int>(Solid::kSphere))
    ->Arg(static_cast<int>(Solid::kBoxWithHole))
    ->Unit(benchmark::kMillisecond);

// Order-2 jets on a 64 x 64 grid: arg 0 the built-in sphere, 1 the STEP
// sphere's face, 2 the box's trimmed plane.
void BM_Jet2(benchmark::State& state) {
  std::unique_ptr<sfc::Surface> builtin = sfc::MakeSphere(10);
  auto sphere = Loaded(Solid::kSphere);
  auto box = Loaded(Solid::kBoxWithHole);
  const sfc::Surface& surface = state.range(0) == 0   ? *builtin
                                : state.range(0) == 1 ? sphere->faces()[0].surface()
                                                      : TrimmedFace(*box).surface();
  const int n = 64;
  for (auto _ : state) {
    for (int i = 0; i < n; ++i) {
      for (int j = 0; j < n; ++j)
        benchmark::DoNotOptimize(surface.Jet((i + 0.5) / n, (j + 0.5) / n, 2));
    }
  }
  state.SetItemsProcessed(state.iterations() * n * n);
  state.SetLabel(state.range(0) == 0   ? "built-in sphere"
                 : state.range(0) == 1 ? "STEP sphere face"
                                       : "box trimmed plane");
}
BENCHMARK(BM_Jet2)->Arg(0)->Arg(1)->Arg(2);

void BM_Contains(benchmark::State& state) {
  auto box = Loaded(Solid::kBoxWithHole);
  const sfc::cad::Face& face = TrimmedFace(*box);
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> uniform(0, 1);
  for (auto _ : state) benchmark::DoNotOptimize(face.Contains(uniform(rng), uniform(rng)));
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_Contains);

// Cells of side 2^-depth at random positions of the trimmed face.
void BM_Classify(benchmark::State& state) {
  auto box = Loaded(Solid::kBoxWithHole);
  const sfc::cad::Face& face = TrimmedFace(*box);
  const int cells = 1 << state.range(0);
  std::mt19937_64 rng(1);
  std::uniform_int_distribution<int> cell(0, cells - 1);
  for (auto _ : state) {
    const double s0 = double(cell(rng)) / cells, t0 = double(cell(rng)) / cells;
    benchmark::DoNotOptimize(face.Classify(s0, s0 + 1.0 / cells, t0, t0 + 1.0 / cells));
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_Classify)->Arg(4)->Arg(8)->Arg(12);

}  // namespace

BENCHMARK_MAIN();
