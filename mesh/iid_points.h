// i.i.d. points on a triangle mesh, uniform by area: the reference that
// tests and benchmarks compare our low-discrepancy sets against (what
// Open3D's sample_points_uniformly gives).
//
// Thread-safety: thread-safe (a pure function of its arguments).
#ifndef SFCSAMPLER_MESH_IID_POINTS_H_
#define SFCSAMPLER_MESH_IID_POINTS_H_

#include <cstdint>
#include <vector>

#include "mesh/triangle_mesh.h"

namespace sfc {

// `n` points: a triangle drawn with probability proportional to its area,
// then uniform barycentric coordinates (the reflected unit square), from a
// std::mt19937_64 seeded with `seed`.
std::vector<Vec3> IidMeshPoints(const TriangleMesh& mesh, size_t n, uint64_t seed);

}  // namespace sfc

#endif  // SFCSAMPLER_MESH_IID_POINTS_H_
