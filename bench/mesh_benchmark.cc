// Mesh sampling figures, printed as tables (not a ctest; run by hand):
//   ./build/bench/mesh_benchmark [count=1000000] [repeats=3] [threads=1] [speed]
// (threads: the cursor's and the triangle order's; the same samples for any count)
// ("speed" prints the uniform row of table 1 only.)
// 1. Speed: `count` samples on the 81 920-triangle icosphere, read from a
//    binary PLY file: cold (read + parse + tree + samples) and warm (samples
//    from the built tree), for the uniform density and |H| + 0.1. Each figure
//    is the median of `repeats` runs.
// 2. Quality: the spherical-triangle discrepancy (evaluation/discrepancy.h, 128
//    random spherical triangles, points pushed radially to the unit sphere)
//    for N = 2^l and 2^l + 2^(l-1), N = 64 .. 24576, ours against i.i.d.
//    points on the same mesh, averaged over 4 seeds, with the least-squares
//    slope of log D against log N (the paper's protocol, docs/ALGORITHM.md).
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "evaluation/discrepancy.h"
#include "mesh/icosphere.h"
#include "mesh/iid_points.h"
#include "mesh/mesh_curve_tree.h"
#include "mesh/mesh_loader.h"
#include "mesh/mesh_sampler.h"
#include "mesh/mesh_writer.h"

namespace sfc {
namespace {

double Seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

std::string ReadAll(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream out;
  out << in.rdbuf();
  return out.str();
}

// Draws [0, n) into one batch (index, u, v, x, y, z: like Open3D's output
// for a mesh without normals, plus our index and barycentric columns).
int g_threads = 1;  // the cursor's threads (argv[3])

size_t DrawAll(const std::shared_ptr<const MeshSampler>& sampler, SampleBatch* batch) {
  auto cursor =
      SampleCursor::Create(sampler, 0, sampler->sequence().count(), {}, {}, g_threads);
  if (!cursor.ok()) {
    std::fprintf(stderr, "%s\n", cursor.status().ToString().c_str());
    std::exit(1);
  }
  batch->Clear();
  size_t total = 0;
  while (true) {
    auto n = (*cursor)->Next(sampler->sequence().count(), batch);
    if (!n.ok() || *n == 0) break;
    total += *n;
  }
  return total;
}

struct Timing {
  double read_parse, tree, samples_cold, warm;
  double cpu_cold, cpu_warm;  // process CPU seconds (std::clock): steadier on a shared machine
  size_t leaves;
};

double CpuSince(std::clock_t since) { return double(std::clock() - since) / CLOCKS_PER_SEC; }

Timing Run(const std::string& path, bool curvature_density, uint64_t count) {
  Timing t{};
  const std::clock_t cpu_start = std::clock();
  const auto start = std::chrono::steady_clock::now();
  auto mesh = LoadMesh(ReadAll(path), path);
  if (!mesh.ok()) {
    std::fprintf(stderr, "%s\n", mesh.status().ToString().c_str());
    std::exit(1);
  }
  t.read_parse = Seconds(start);
  auto t1 = std::chrono::steady_clock::now();
  auto surface = MeshSurface::Create(*std::move(mesh), curvature_density);
  auto density = curvature_density ? MeanCurvatureMeshDensity(0.1) : UniformMeshDensity();
  MeshTreeOptions options;
  options.count = count;
  options.threads = g_threads;
  auto tree = MeshCurveTree::Build(surface, density, options);
  if (!tree.ok()) {
    std::fprintf(stderr, "%s\n", tree.status().ToString().c_str());
    std::exit(1);
  }
  t.tree = Seconds(t1);
  t.leaves = (*tree)->leaf_count();
  auto sampler = std::make_shared<MeshSampler>(*tree, Sequence(SequenceKind::kJittered, count, 1));
  SampleBatch batch;
  auto t2 = std::chrono::steady_clock::now();
  DrawAll(sampler, &batch);
  t.samples_cold = Seconds(t2);
  t.cpu_cold = CpuSince(cpu_start);
  const std::clock_t cpu_warm = std::clock();
  auto t3 = std::chrono::steady_clock::now();
  DrawAll(sampler, &batch);
  t.warm = Seconds(t3);
  t.cpu_warm = CpuSince(cpu_warm);
  return t;
}

std::vector<Vec3> OnSphere(const SampleBatch& b) {
  std::vector<Vec3> out;
  for (size_t i = 0; i < b.size(); ++i) {
    const Vec3 p{b.x[i], b.y[i], b.z[i]};
    out.push_back(p * (1 / Norm(p)));
  }
  return out;
}

std::vector<Vec3> IidOnSphere(const TriangleMesh& mesh, size_t n, uint64_t seed) {
  std::vector<Vec3> out = IidMeshPoints(mesh, n, seed);
  for (Vec3& p : out) p = p * (1 / Norm(p));
  return out;
}


}  // namespace
}  // namespace sfc

int main(int argc, char** argv) {
  using namespace sfc;
  const uint64_t count = argc > 1 ? std::stoull(argv[1]) : 1000000;
  const int repeats = argc > 2 ? std::stoi(argv[2]) : 3;
  g_threads = argc > 3 ? std::stoi(argv[3]) : 1;
  const TriangleMesh sphere = MakeIcosphere(6);
  const auto dir = std::filesystem::temp_directory_path() /
                   ("sfc_mesh_bench_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "icosphere80k.ply").string();
  std::ofstream(path, std::ios::binary) << MeshToPly(sphere, /*binary=*/true);

  std::printf("# %llu samples on the icosphere (%zu triangles, binary PLY), median of %d runs\n",
              static_cast<unsigned long long>(count), sphere.triangles.size(), repeats);
  std::printf("| density | leaves | read+parse s | tree s | samples s | cold total s | warm s | "
              "cold cpu s | warm cpu s | warm M samples/s (cpu) |\n"
              "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  const bool quality = argc <= 4 || std::string(argv[4]) != "speed";
  for (bool curvature : {false, true}) {
    if (curvature && !quality) break;
    std::vector<double> rp, tr, sc, cold, warm, cpu_cold, cpu_warm;
    size_t leaves = 0;
    for (int r = 0; r < repeats; ++r) {
      const Timing t = Run(path, curvature, count);
      rp.push_back(t.read_parse), tr.push_back(t.tree), sc.push_back(t.samples_cold);
      cold.push_back(t.read_parse + t.tree + t.samples_cold), warm.push_back(t.warm);
      cpu_cold.push_back(t.cpu_cold), cpu_warm.push_back(t.cpu_warm);
      leaves = t.leaves;
    }
    std::printf("| %s | %zu | %.3f | %.3f | %.3f | %.3f | %.3f | %.3f | %.3f | %.1f |\n",
                curvature ? "mean:floor=0.1" : "uniform", leaves, Median(rp), Median(tr),
                Median(sc), Median(cold), Median(warm), Median(cpu_cold), Median(cpu_warm),
                count / Median(cpu_warm) / 1e6);
  }

  if (!quality) {
    std::filesystem::remove_all(dir);
    return 0;
  }
  std::printf("\n# spherical-triangle discrepancy, 128 triangles, mean of 4 seeds\n");
  std::printf("| N | ours | i.i.d. on the mesh |\n|---:|---:|---:|\n");
  auto surface = MeshSurface::Create(sphere, false);
  auto tree = MeshCurveTree::Build(surface, UniformMeshDensity(), {});
  std::vector<double> ns, ours, iid;
  for (int l = 6; l <= 14; ++l) {
    for (uint64_t n : {uint64_t{1} << l, (uint64_t{1} << l) + (uint64_t{1} << (l - 1))}) {
      double d_ours = 0, d_iid = 0;
      for (uint64_t seed = 1; seed <= 4; ++seed) {
        auto sampler =
            std::make_shared<MeshSampler>(*tree, Sequence(SequenceKind::kJittered, n, seed));
        SampleBatch batch;
        DrawAll(sampler, &batch);
        d_ours += SphericalTriangleDiscrepancy(OnSphere(batch), 128, 100 + seed) / 4;
        d_iid += SphericalTriangleDiscrepancy(IidOnSphere(sphere, n, seed), 128, 100 + seed) / 4;
      }
      ns.push_back(n), ours.push_back(d_ours), iid.push_back(d_iid);
      std::printf("| %llu | %.3e | %.3e |\n", static_cast<unsigned long long>(n), d_ours, d_iid);
    }
  }
  std::printf("| slope | %.3f | %.3f |\n", LogLogSlope(ns, ours), LogLogSlope(ns, iid));
  double lo = HUGE_VAL, hi = 0;
  for (size_t t = 0; t < sphere.triangles.size(); ++t) {
    // Spherical over flat area of each triangle (Van Oosterom-Strackee excess).
    const auto& f = sphere.triangles[t];
    const Vec3 &a = sphere.positions[f[0]], &b = sphere.positions[f[1]],
               &c = sphere.positions[f[2]];
    const double excess = 2 * std::atan2(std::abs(Dot(a, Cross(b, c))),
                                         1 + Dot(a, b) + Dot(b, c) + Dot(c, a));
    const double ratio = excess / (0.5 * Norm(sphere.FaceCross(t)));
    lo = std::min(lo, ratio), hi = std::max(hi, ratio);
  }
  std::printf("\nspherical / flat area per triangle: %.6f .. %.6f (the bias of pushing points to "
              "the sphere)\n", lo, hi);
  std::filesystem::remove_all(dir);
  return 0;
}
