// A mesh handed over as NumPy arrays, as its canonical PLY bytes: binary
// little-endian, vertex x y z [nx ny nz] [weight] as float64, faces as `list
// uchar int vertex_indices`. The one writer of those bytes: Python's
// meshes.canonical_ply() checks its arguments (naming what is wrong) and
// calls this through _core.canonical_ply; sample_many's in-memory meshes call
// it directly, so that many meshes need neither the GIL nor NumPy's
// structured arrays.
//
// Thread-safety: a pure function of its arguments.
#ifndef SFCSAMPLER_PYTHON_BINDINGS_MESH_ARRAYS_H_
#define SFCSAMPLER_PYTHON_BINDINGS_MESH_ARRAYS_H_

#include <cstddef>
#include <cstdint>
#include <string>

namespace sfc::python {

// The vertex property per-vertex weights travel in (density "vertex:weight").
inline constexpr char kWeightProperty[] = "weight";

// The canonical PLY of `vertex_count` vertices (x, y, z float64, row-major),
// their `normals` (nx, ny, nz, row-major) and `weights` (one each), either
// or both null for none, and `face_count` triangles (vertex indices,
// row-major, int32 or int64 as `wide_faces` says); or false when the mesh
// fails a check canonical_ply() makes of the vertices and faces (fewer than 3
// vertices, a coordinate that is not finite, no faces, an index outside [0,
// vertex_count), more than 2^31 vertices): the caller then lets
// canonical_ply() name the error. Normals and weights are written as given.
bool CanonicalPly(const double* vertices, size_t vertex_count, const double* normals,
                  const double* weights, const void* faces, bool wide_faces, size_t face_count,
                  std::string* out);

}  // namespace sfc::python

#endif  // SFCSAMPLER_PYTHON_BINDINGS_MESH_ARRAYS_H_
