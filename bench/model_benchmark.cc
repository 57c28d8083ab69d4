// Models against the built-in sphere, side by side in one run (issue 11's
// speed table): the cold time (read and parse the file, build the trees,
// draw every sample) and the leaves for N samples of the STEP box with a
// fillet and a hole and of the STEP sphere, each next to the built-in sphere
// measured in the same loop. Prints a Markdown table; not a ctest.
//   taskset -c 0 ./build/bench/model_benchmark [count=1000000] [repeats=3] [only=NAME]
// (only: run just the models whose name contains NAME, e.g. "box" to profile it)
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <unistd.h>
#include <vector>

#include "cad/fixtures.h"
#include "engine/sampling_engine.h"
#include "kinds/registered_kinds.h"

namespace {

using Clock = std::chrono::steady_clock;

struct Run {
  double seconds = 0;
  double start_seconds = 0;  // of it: the engine, the file and the trees, before the first sample
  uint64_t leaves = 0, samples = 0;
};

// One cold request, in process: a fresh engine (no cached model or tree).
Run Cold(const std::string& surface, uint64_t count) {
  sfc::DirectTreeSource source;
  sfc::FileModelSource files;
  sfc::EngineLimits limits;
  limits.generation_threads = 1;
  const auto start = Clock::now();
  sfc::SamplingEngine engine(sfc::RegisteredSurfaceKinds(), limits, &source, &files);
  sfc::SampleRequest r;
  r.tree.surface = surface;
  r.count = count;
  r.seed = 1;
  auto job = engine.Start(r);
  if (!job.ok()) {
    std::fprintf(stderr, "%s: %s\n", surface.c_str(), job.status().ToString().c_str());
    std::exit(1);
  }
  Run run;
  run.start_seconds = std::chrono::duration<double>(Clock::now() - start).count();
  sfc::SampleBatch batch;
  while (true) {
    batch.Clear();
    auto n = job->cursor->Next(65536, &batch);
    if (!n.ok() || *n == 0) break;
    run.samples += *n;
  }
  run.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  run.leaves = job->tree.lookup.any->leaves();
  return run;
}

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  const uint64_t count = argc > 1 ? std::strtoull(argv[1], nullptr, 10) : 1000000;
  const int repeats = argc > 2 ? std::atoi(argv[2]) : 3;
  const std::string only = argc > 3 ? argv[3] : "";
  const std::string dir = "/tmp/sfc_model_bench_" + std::to_string(::getpid());
  std::system(("mkdir -p " + dir).c_str());
  auto written = sfc::cad::fixtures::WriteAll(dir);
  if (!written.ok()) {
    std::fprintf(stderr, "%s\n", written.status().ToString().c_str());
    return 1;
  }
  const std::vector<std::pair<std::string, std::string>> models = {
      {"STEP box with a fillet and a hole (8 faces, 2 trimmed)",
       "step:" + dir + "/box_with_hole.step"},
      {"STEP sphere", "step:" + dir + "/sphere.step"},
  };
  std::printf("N = %llu, cold (parse + trees + samples, one thread), median of %d, each model "
              "next to the built-in sphere in the same loop\n\n",
              static_cast<unsigned long long>(count), repeats);
  std::printf("| surface | cold s | of it: file + trees, samples | leaves | built-in sphere cold s "
              "| of it: tree, samples | its leaves | time ratio |\n");
  std::printf("|---|---:|---:|---:|---:|---:|---:|---:|\n");
  for (const auto& [name, spec] : models) {
    if (name.find(only) == std::string::npos) continue;
    std::vector<double> model_s, model_start, sphere_s, sphere_start;
    Run m, s;
    for (int i = 0; i < repeats; ++i) {
      m = Cold(spec, count);
      s = Cold("sphere", count);
      model_s.push_back(m.seconds), sphere_s.push_back(s.seconds);
      model_start.push_back(m.start_seconds), sphere_start.push_back(s.start_seconds);
    }
    // The parts are each one's own median (they need not add up exactly).
    auto samples = [](const std::vector<double>& all, const std::vector<double>& start) {
      std::vector<double> d;
      for (size_t i = 0; i < all.size(); ++i) d.push_back(all[i] - start[i]);
      return Median(d);
    };
    std::printf("| %s | %.3f | %.3f, %.3f | %llu | %.3f | %.3f, %.3f | %llu | %.2f |\n",
                name.c_str(), Median(model_s), Median(model_start), samples(model_s, model_start),
                static_cast<unsigned long long>(m.leaves), Median(sphere_s), Median(sphere_start),
                samples(sphere_s, sphere_start), static_cast<unsigned long long>(s.leaves),
                Median(model_s) / Median(sphere_s));
  }
  std::system(("rm -rf " + dir).c_str());
  return 0;
}
