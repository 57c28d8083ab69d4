#include "mesh/curvature.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "core/vector_math.h"

namespace sfc {

VertexCurvature ComputeVertexCurvature(const TriangleMesh& mesh) {
  const size_t nv = mesh.positions.size();
  VertexCurvature out;
  out.gaussian.assign(nv, 0);
  out.mean.assign(nv, 0);
  out.mixed_area.assign(nv, 0);
  std::vector<double> angle_sum(nv, 0);
  std::vector<Vec3> laplace(nv);        // sum_j (cot a + cot b)(x_i - x_j)
  std::vector<Vec3> face_normals(nv);   // area-weighted, when the file has no normals
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    if (IsDegenerateTriangle(mesh, t)) continue;
    const auto& f = mesh.triangles[t];
    const Vec3 cross = mesh.FaceCross(t);
    const double area = 0.5 * Norm(cross);
    double cot[3], angle[3];
    for (int c = 0; c < 3; ++c) {
      const Vec3& p = mesh.positions[f[c]];
      const Vec3 a = mesh.positions[f[(c + 1) % 3]] - p;
      const Vec3 b = mesh.positions[f[(c + 2) % 3]] - p;
      const double cos_part = Dot(a, b);
      const double sin_part = Norm(Cross(a, b));
      cot[c] = cos_part / sin_part;
      angle[c] = math::Atan2(sin_part, cos_part);
    }
    const bool obtuse = angle[0] > M_PI / 2 || angle[1] > M_PI / 2 || angle[2] > M_PI / 2;
    for (int c = 0; c < 3; ++c) {
      const uint32_t i = f[c], j = f[(c + 1) % 3], k = f[(c + 2) % 3];
      angle_sum[i] += angle[c];
      face_normals[i] += cross;
      // Edge (i, j) is opposite corner c + 2; edge (i, k) opposite corner c + 1.
      const Vec3 eij = mesh.positions[i] - mesh.positions[j];
      const Vec3 eik = mesh.positions[i] - mesh.positions[k];
      laplace[i] += eij * cot[(c + 2) % 3] + eik * cot[(c + 1) % 3];
      if (!obtuse) {
        out.mixed_area[i] +=
            (Dot(eij, eij) * cot[(c + 2) % 3] + Dot(eik, eik) * cot[(c + 1) % 3]) / 8;
      } else {
        out.mixed_area[i] += angle[c] > M_PI / 2 ? area / 2 : area / 4;
      }
    }
  }
  std::vector<bool> boundary(nv, false);
  ForEachEdge(mesh, [&boundary](uint32_t a, uint32_t b, uint32_t n) {
    if (n == 1) boundary[a] = boundary[b] = true;
  });
  for (size_t i = 0; i < nv; ++i) {
    const double area = out.mixed_area[i];
    if (!(area > 0)) continue;
    out.gaussian[i] = ((boundary[i] ? M_PI : 2 * M_PI) - angle_sum[i]) / area;
    const Vec3 k = laplace[i] * (1 / (2 * area));
    const Vec3 n = mesh.normals.empty() ? face_normals[i] : mesh.normals[i];
    const double h = Norm(k) / 2;
    out.mean[i] = Dot(k, n) < 0 ? -h : h;
  }
  return out;
}

}  // namespace sfc
