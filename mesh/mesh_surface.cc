#include "mesh/mesh_surface.h"

namespace sfc {

std::shared_ptr<const MeshSurface> MeshSurface::Create(TriangleMesh mesh, bool with_curvature) {
  auto surface = std::shared_ptr<MeshSurface>(new MeshSurface(std::move(mesh)));
  const TriangleMesh& m = surface->mesh_;
  surface->face_normals_.resize(m.triangles.size());
  surface->areas_.resize(m.triangles.size());
  for (size_t t = 0; t < m.triangles.size(); ++t) {
    const Vec3 c = m.FaceCross(t);
    const double len = Norm(c);
    if (len > 0 && !IsDegenerateTriangle(m, t, len)) {
      surface->face_normals_[t] = c * (1 / len);
      surface->areas_[t] = 0.5 * len;
    }
  }
  if (with_curvature) surface->curvature_ = ComputeVertexCurvature(m);
  return surface;
}

Vec3 MeshSurface::Normal(size_t t, const std::array<double, 3>& b) const {
  if (mesh_.normals.empty()) return face_normals_[t];
  const auto& f = mesh_.triangles[t];
  const Vec3 n =
      mesh_.normals[f[0]] * b[0] + mesh_.normals[f[1]] * b[1] + mesh_.normals[f[2]] * b[2];
  const double len = Norm(n);
  return len > 0 ? n * (1 / len) : face_normals_[t];
}

MeshPoint MeshSurface::Attributes(size_t t, const std::array<double, 3>& b) const {
  const auto& f = mesh_.triangles[t];
  MeshPoint p;
  p.position = Point(t, b);
  if (!mesh_.weights.empty()) {
    p.weight = mesh_.weights[f[0]] * b[0] + mesh_.weights[f[1]] * b[1] + mesh_.weights[f[2]] * b[2];
  }
  if (has_curvature()) {
    const auto& k = curvature_.gaussian;
    const auto& h = curvature_.mean;
    p.gaussian_curvature = k[f[0]] * b[0] + k[f[1]] * b[1] + k[f[2]] * b[2];
    p.mean_curvature = h[f[0]] * b[0] + h[f[1]] * b[1] + h[f[2]] * b[2];
  }
  return p;
}

}  // namespace sfc
