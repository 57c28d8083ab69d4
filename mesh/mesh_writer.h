// Writes a TriangleMesh as OBJ or PLY (binary little-endian or ASCII): test
// fixtures, benchmarks and tools. Doubles are written with 17 significant
// digits (text) or as float64 (binary), so a mesh reads back exactly.
//
// Thread-safety: thread-safe (pure functions).
#ifndef SFCSAMPLER_MESH_MESH_WRITER_H_
#define SFCSAMPLER_MESH_MESH_WRITER_H_

#include <string>

#include "mesh/triangle_mesh.h"

namespace sfc {

// OBJ text: "v", optional "vn" (one per vertex), "f a//a b//b c//c".
std::string MeshToObj(const TriangleMesh& mesh);

// PLY with vertex x y z (double), optional nx ny nz, optional weights under
// the property name `weight_property` (double), and faces as
// "list uchar int vertex_indices".
std::string MeshToPly(const TriangleMesh& mesh, bool binary,
                      const std::string& weight_property = "weight");

}  // namespace sfc

#endif  // SFCSAMPLER_MESH_MESH_WRITER_H_
