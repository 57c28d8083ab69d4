// A mesh handed over as NumPy arrays, as the canonical PLY bytes that
// python/sfcsampler/meshes.py's canonical_ply() writes for (vertices, faces)
// without normals or weights, made in C++ so that many meshes need neither
// the GIL nor NumPy's structured arrays (sample_many's in-memory meshes).
//
// Thread-safety: a pure function of its arguments.
#ifndef SFCSAMPLER_PYTHON_BINDINGS_MESH_ARRAYS_H_
#define SFCSAMPLER_PYTHON_BINDINGS_MESH_ARRAYS_H_

#include <cstddef>
#include <cstdint>
#include <string>

namespace sfc::python {

// The canonical PLY of `vertex_count` vertices (x, y, z float64, row-major)
// and `face_count` triangles (vertex indices, row-major, int32 or int64 as
// `wide_faces` says), or false when the mesh fails a check canonical_ply()
// makes (fewer than 3 vertices, a coordinate that is not finite, no faces, an
// index outside [0, vertex_count), more than 2^31 vertices): the caller then
// lets canonical_ply() name the error.
bool CanonicalPly(const double* vertices, size_t vertex_count, const void* faces, bool wide_faces,
                  size_t face_count, std::string* out);

}  // namespace sfc::python

#endif  // SFCSAMPLER_PYTHON_BINDINGS_MESH_ARRAYS_H_
