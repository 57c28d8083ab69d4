// A direct reader for the plainest binary PLY: the layout the Python package
// writes for meshes given as arrays (python/sfcsampler/meshes.py) and most
// scanners and exporters write too. CGAL's reader (mesh/mesh_loader.cc)
// reads every PLY through an istream, a virtual call per value; for a mesh of
// a few thousand triangles that was about a tenth of the whole time from
// bytes to samples. This reader copies the values straight out of the bytes.
//
// It takes a file only when it is sure to read it as the CGAL path does:
//   - "ply", then "format binary_little_endian 1.0", then only "comment",
//     "obj_info", "element" and "property" lines up to "end_header", each
//     ending in '\n';
//   - an element "vertex" of scalar float or double properties, then an
//     element "face" whose one property is "list uchar int vertex_indices"
//     (uint8 and int32, or uint for the indices), and no other element;
//   - every face a triangle, every index below the vertex count, and the
//     bytes ending exactly after the last face.
// Anything else (other layouts, damaged files) returns nullopt and goes to
// the CGAL path, which reads it or gives its error. The mesh is the one the
// CGAL path makes (same values, triangles and stats), before FinalizeMesh.
// It does not poll MeshLoadOptions::check: one pass, linear in the bytes
// (which max_bytes bounds), copying at memory speed.
//
// Thread-safety: a pure function.
#ifndef SFCSAMPLER_MESH_PLAIN_PLY_H_
#define SFCSAMPLER_MESH_PLAIN_PLY_H_

#include <optional>
#include <string>

#include "absl/strings/string_view.h"
#include "mesh/triangle_mesh.h"

namespace sfc {

// The mesh of `bytes` when it is a plain binary PLY as above; `weight_property`
// as in MeshLoadOptions (empty = none; a name the vertex lacks: nullopt).
std::optional<TriangleMesh> ReadPlainBinaryPly(absl::string_view bytes, absl::string_view name,
                                               const std::string& weight_property);

}  // namespace sfc

#endif  // SFCSAMPLER_MESH_PLAIN_PLY_H_
