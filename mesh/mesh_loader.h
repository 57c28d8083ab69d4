// Loads OBJ and PLY triangle meshes from bytes in memory (the server never
// opens a client's path), through Debian-packaged readers: tinyobjloader for
// OBJ and CGAL's PLY reader for PLY (ASCII and binary, both byte orders,
// named vertex properties kept, so a user can name one as per-vertex weights).
//
// Polygons are split into triangle fans (counted in MeshStats). Errors name
// the mesh: INVALID_ARGUMENT for an empty mesh, a truncated or malformed file,
// a non-finite coordinate, an index past the vertices, a missing weight
// property; RESOURCE_EXHAUSTED for input past MeshLoadOptions::max_bytes.
//
// Thread-safety: the functions are thread-safe (no shared state).
#ifndef SFCSAMPLER_MESH_MESH_LOADER_H_
#define SFCSAMPLER_MESH_MESH_LOADER_H_

#include <cstdint>
#include <functional>
#include <optional>
#include <string>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "mesh/triangle_mesh.h"
#include "request/model_spec.h"

namespace sfc {

struct MeshLoadOptions {
  // Input larger than this is refused with RESOURCE_EXHAUSTED before parsing.
  // Default 512 MiB. The parsed mesh takes at most a few times the input size.
  uint64_t max_bytes = uint64_t{512} << 20;
  // ModelFormat::kObj or kPly (request/model_spec.h's one enum of model
  // formats; a CAD format is INVALID_ARGUMENT); nullopt: PLY when the bytes
  // start with "ply", otherwise OBJ.
  std::optional<ModelFormat> format = std::nullopt;
  // Name of a PLY vertex property (any numeric type) read as per-vertex
  // weights (MeshDensityKind::kVertexWeight); empty = none. OBJ has no named
  // vertex properties: naming one for an OBJ file is INVALID_ARGUMENT.
  std::string weight_property;
  // Asked between parts of the work (every 65536 PLY items, after the OBJ
  // reader); a non-OK status stops the load, which returns it. Empty: never.
  std::function<absl::Status()> check;
};

// Parses `bytes` as a mesh called `name` (used in messages only), then
// FinalizeMesh(). Vertex normals are kept when the file gives one per vertex
// (PLY nx, ny, nz; OBJ vn when every corner of a vertex uses the same vn).
absl::StatusOr<TriangleMesh> LoadMesh(absl::string_view bytes, absl::string_view name,
                                      const MeshLoadOptions& options = {});

// Reads a local file (for the CLI and tools; the size is checked against
// max_bytes before reading) and calls LoadMesh with the file's extension as
// the format when options.format is kAuto. NOT_FOUND when it cannot be read.
absl::StatusOr<TriangleMesh> LoadMeshFile(const std::string& path,
                                          const MeshLoadOptions& options = {});

// The peak memory that LoadMesh of `bytes` in `format` (kObj or kPly) and
// MeshSurface::Create of its mesh, with curvature, may take beyond the bytes
// themselves: what a server reserves before the parse starts. The worst
// files make a triangle of every two bytes (long faces of one-digit corners:
// OBJ, ASCII PLY) or of every byte (binary PLY with uchar indices), a triangle
// costing about 50 bytes read and kept, or a face of every 8 bytes (OBJ
// "f 1 2 3" lines: tinyobjloader's faces cost about 190 bytes). Measured by
// bench/parse_memory (docs/MODELS.md): at most 24.5 bytes a byte of OBJ, 24.7
// of ASCII PLY and 49.1 of binary PLY; reserved with a margin of 1.3, plus
// 1 MiB for any file.
uint64_t MeshParseMemoryBytes(ModelFormat format, absl::string_view bytes);

}  // namespace sfc

#endif  // SFCSAMPLER_MESH_MESH_LOADER_H_
