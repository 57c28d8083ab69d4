// Discrete curvature per vertex of a triangle mesh, by the operators of
// Meyer, Desbrun, Schroeder and Barr, "Discrete Differential-Geometry
// Operators for Triangulated 2-Manifolds" (VisMath 2002 / Springer 2003):
//   Gaussian curvature  K(x_i) = (2 pi - sum_j theta_j) / A_mixed        (Sect. 4, eq. 9)
//   mean curvature      H(x_i) = |K_vec| / 2,  K_vec = 1 / (2 A_mixed) *
//                        sum_j (cot alpha_ij + cot beta_ij) (x_i - x_j)   (Sect. 3.4, eq. 8)
// with A_mixed the mixed Voronoi area (Sect. 3.4, Fig. 4): the Voronoi area
// of the vertex in non-obtuse triangles, half / a quarter of an obtuse
// triangle's area. H is signed: positive where K_vec points along the vertex
// normal (the file's, else the area-weighted face normals), so a sphere with
// outward normals has H = 1/r. No mesh-curvature library is packaged in
// Debian bookworm (libigl and CGAL 5.5 have none we can use), hence this file.
//
// Boundary vertices use pi instead of 2 pi in the angle deficit (the
// geodesic-curvature form); their cotangent sum misses the outside ring, so
// H there is an estimate only. Degenerate triangles are ignored. A vertex
// with no area (isolated, or only degenerate triangles) gets K = H = 0.
//
// Thread-safety: thread-safe (a pure function).
#ifndef SFCSAMPLER_MESH_CURVATURE_H_
#define SFCSAMPLER_MESH_CURVATURE_H_

#include <vector>

#include "mesh/triangle_mesh.h"

namespace sfc {

struct VertexCurvature {
  std::vector<double> gaussian;   // K per vertex (1 / length^2)
  std::vector<double> mean;       // H per vertex (1 / length), signed as above
  std::vector<double> mixed_area; // A_mixed per vertex
};

VertexCurvature ComputeVertexCurvature(const TriangleMesh& mesh);

}  // namespace sfc

#endif  // SFCSAMPLER_MESH_CURVATURE_H_
