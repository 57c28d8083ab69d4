#include "mesh/icosphere.h"

#include <cmath>
#include <map>
#include <utility>

#include "base/status_macros.h"

namespace sfc {

TriangleMesh MakeIcosphere(int subdivisions, bool with_normals) {
  const double g = (1 + std::sqrt(5.0)) / 2;
  TriangleMesh mesh;
  mesh.name = "icosphere";
  mesh.positions = {{-1, g, 0}, {1, g, 0}, {-1, -g, 0}, {1, -g, 0}, {0, -1, g}, {0, 1, g},
                    {0, -1, -g}, {0, 1, -g}, {g, 0, -1}, {g, 0, 1}, {-g, 0, -1}, {-g, 0, 1}};
  mesh.triangles = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                    {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                    {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                    {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (Vec3& p : mesh.positions) p = p * (1 / Norm(p));
  for (int s = 0; s < subdivisions; ++s) {
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> midpoint;
    auto mid = [&](uint32_t a, uint32_t b) {
      const auto key = std::make_pair(std::min(a, b), std::max(a, b));
      auto [it, inserted] = midpoint.emplace(key, static_cast<uint32_t>(mesh.positions.size()));
      if (inserted) {
        const Vec3 m = mesh.positions[a] + mesh.positions[b];
        mesh.positions.push_back(m * (1 / Norm(m)));
      }
      return it->second;
    };
    std::vector<std::array<uint32_t, 3>> next;
    next.reserve(mesh.triangles.size() * 4);
    for (const auto& t : mesh.triangles) {
      const uint32_t ab = mid(t[0], t[1]), bc = mid(t[1], t[2]), ca = mid(t[2], t[0]);
      next.push_back({t[0], ab, ca});
      next.push_back({t[1], bc, ab});
      next.push_back({t[2], ca, bc});
      next.push_back({ab, bc, ca});
    }
    mesh.triangles = std::move(next);
  }
  if (with_normals) mesh.normals = mesh.positions;
  const absl::Status status = FinalizeMesh(&mesh);  // fills stats; cannot fail here
  (void)status;
  return mesh;
}

}  // namespace sfc
