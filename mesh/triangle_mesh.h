// A triangle mesh as sfc_mesh samples it: positions, triangles, optional
// per-vertex normals and weights, and what loading found (degenerate
// triangles, non-manifold edges, triangulated polygons).
//
// Value type; thread-compatible. Immutable once FinalizeMesh() accepted it.
#ifndef SFCSAMPLER_MESH_TRIANGLE_MESH_H_
#define SFCSAMPLER_MESH_TRIANGLE_MESH_H_

#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "core/types/vec3.h"

namespace sfc {

struct MeshStats {
  uint64_t vertices = 0;
  uint64_t faces = 0;                  // faces as the file lists them (a polygon counts once)
  uint64_t triangulated_polygons = 0;  // faces with more than 3 corners, split into a fan
  uint64_t degenerate_triangles = 0;  // zero-area triangles: kept in the index space, never sampled
  uint64_t non_manifold_edges = 0;     // edges of more than two triangles (CountEdges)
  uint64_t boundary_edges = 0;         // edges of exactly one triangle (CountEdges)
  double area = 0;                     // total area of the non-degenerate triangles
  // The box of the vertices the triangles use: it holds every sample (a
  // sample is a convex combination of its triangle's corners).
  Vec3 lo, hi;
};

struct TriangleMesh {
  std::string name;                             // for messages (a file name or a label)
  std::vector<Vec3> positions;                  // one per vertex, finite
  std::vector<std::array<uint32_t, 3>> triangles;  // counter-clockwise seen from the normal side
  std::vector<Vec3> normals;                    // per vertex (unit), or empty: use face normals
  std::vector<double> weights;                  // per vertex (>= 0, finite), or empty
  MeshStats stats;                              // filled by FinalizeMesh()

  // Twice the area and the unnormalised normal of triangle t.
  Vec3 FaceCross(size_t t) const {
    const auto& f = triangles[t];
    return Cross(positions[f[1]] - positions[f[0]], positions[f[2]] - positions[f[0]]);
  }
};

// True when triangle t has (numerically) no area: a repeated corner, or
// |e1 x e2| <= 1e-12 * (longest edge)^2. Such triangles are never sampled.
bool IsDegenerateTriangle(const TriangleMesh& mesh, size_t t);
// The same test, given cross_norm = Norm(mesh.FaceCross(t)) (computed once
// by callers that also need the area or the normal).
bool IsDegenerateTriangle(const TriangleMesh& mesh, size_t t, double cross_norm);

// Calls f(a, b, n) once per distinct edge {a, b} (a < b) of the
// non-degenerate triangles, n = how many of them have it, in order of a.
// O(triangles): edges are bucketed by their lower vertex.
void ForEachEdge(const TriangleMesh& mesh,
                 const std::function<void(uint32_t a, uint32_t b, uint32_t n)>& f);

// Checks a freshly built mesh and fills `stats` but the edge counts.
// Errors (INVALID_ARGUMENT, naming mesh->name): no triangles or only
// degenerate ones, a corner index past the vertices, a non-finite
// coordinate, normal or weight, a negative weight, normals or weights whose
// count differs from the vertex count, a size out of CheckSize's range
// (core/area_estimator.h) over the vertices the triangles use (vertices no
// triangle uses do not count). Degenerate triangles are counted and kept (so
// triangle indices stay those of the file); non-manifold edges are
// accepted.
absl::Status FinalizeMesh(TriangleMesh* mesh);

// Fills stats.boundary_edges and stats.non_manifold_edges (ForEachEdge).
// Not part of FinalizeMesh: nothing on the way to samples needs them, and
// for a small mesh they cost a few percent of its time from bytes to samples.
void CountEdges(TriangleMesh* mesh);

}  // namespace sfc

#endif  // SFCSAMPLER_MESH_TRIANGLE_MESH_H_
