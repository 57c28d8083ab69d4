// A loaded mesh ready to sample: the TriangleMesh, its face normals and,
// when asked for, per-vertex curvature (mesh/curvature.h). Evaluates points,
// normals and density inputs at barycentric coordinates.
//
// Thread-safety: immutable after Create(); thread-safe. Shared as
// std::shared_ptr<const MeshSurface> by trees and cursors.
#ifndef SFCSAMPLER_MESH_MESH_SURFACE_H_
#define SFCSAMPLER_MESH_MESH_SURFACE_H_

#include <array>
#include <memory>
#include <vector>

#include "mesh/curvature.h"
#include "mesh/mesh_density.h"
#include "mesh/triangle_mesh.h"

namespace sfc {

class MeshSurface {
 public:
  // REQUIRES: FinalizeMesh(&mesh) succeeded (LoadMesh and MakeIcosphere do it).
  // `with_curvature` computes per-vertex K and H (O(triangles)).
  static std::shared_ptr<const MeshSurface> Create(TriangleMesh mesh, bool with_curvature);

  const TriangleMesh& mesh() const { return mesh_; }
  bool has_curvature() const { return !curvature_.gaussian.empty(); }
  const VertexCurvature& curvature() const { return curvature_; }
  size_t triangle_count() const { return mesh_.triangles.size(); }

  // b = barycentric coordinates for corners (0, 1, 2) of triangle t.
  Vec3 Point(size_t t, const std::array<double, 3>& b) const {
    const auto& f = mesh_.triangles[t];
    return mesh_.positions[f[0]] * b[0] + mesh_.positions[f[1]] * b[1] +
           mesh_.positions[f[2]] * b[2];
  }
  // Unit normal: interpolated vertex normals when the mesh has them, else the face normal.
  Vec3 Normal(size_t t, const std::array<double, 3>& b) const;
  // The density's inputs at a point (curvature only when computed).
  MeshPoint Attributes(size_t t, const std::array<double, 3>& b) const;
  const Vec3& FaceNormal(size_t t) const { return face_normals_[t]; }
  // 0.5 |FaceCross(t)|, computed once; 0 for degenerate triangles.
  double area(size_t t) const { return areas_[t]; }
  // IsDegenerateTriangle(mesh(), t), computed once.
  bool degenerate(size_t t) const { return face_normals_[t] == Vec3{}; }

 private:
  explicit MeshSurface(TriangleMesh mesh) : mesh_(std::move(mesh)) {}

  TriangleMesh mesh_;
  std::vector<Vec3> face_normals_;  // unit; zero for degenerate triangles
  std::vector<double> areas_;
  VertexCurvature curvature_;
};

}  // namespace sfc

#endif  // SFCSAMPLER_MESH_MESH_SURFACE_H_
