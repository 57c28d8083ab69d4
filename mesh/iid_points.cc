#include "mesh/iid_points.h"

#include <random>

namespace sfc {

std::vector<Vec3> IidMeshPoints(const TriangleMesh& mesh, size_t n, uint64_t seed) {
  std::vector<double> areas;
  areas.reserve(mesh.triangles.size());
  for (size_t t = 0; t < mesh.triangles.size(); ++t) areas.push_back(Norm(mesh.FaceCross(t)));
  std::discrete_distribution<size_t> pick(areas.begin(), areas.end());
  std::uniform_real_distribution<double> u01(0, 1);
  std::mt19937_64 rng(seed);
  std::vector<Vec3> out;
  out.reserve(n);
  for (size_t i = 0; i < n; ++i) {
    const auto& f = mesh.triangles[pick(rng)];
    double a = u01(rng), b = u01(rng);
    if (a + b > 1) a = 1 - a, b = 1 - b;
    out.push_back(mesh.positions[f[0]] * (1 - a - b) + mesh.positions[f[1]] * a +
                  mesh.positions[f[2]] * b);
  }
  return out;
}

}  // namespace sfc
