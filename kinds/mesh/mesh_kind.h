// Triangle meshes (obj:FILE, ply:FILE or FORMAT:sha256=HEX) through mesh/: a
// tree over the mesh's triangles and a cursor with the triangle column (u, v
// are the barycentric coordinates of the triangle's corners 1 and 2).
//
// Densities on a mesh: uniform; gaussian and mean (|K|, |H|) and
// gaussian:offset=F and mean:offset=F (|K| + F, |H| + F), from per-vertex
// discrete curvature (mesh/curvature.h); expr:BODY in x, y, z; vertex:NAME, the
// PLY vertex property NAME read as per-vertex weights and interpolated
// linearly over each triangle. gaussian:floor=F with F > 0 (max(|K|, F)
// elsewhere) is refused: sfcsampler-3 gave meshes |K| + F for it, and the
// same request may not give other bytes under the same algorithm version.
#ifndef SFCSAMPLER_KINDS_MESH_MESH_KIND_H_
#define SFCSAMPLER_KINDS_MESH_MESH_KIND_H_

#include <memory>

#include "engine/surface_kind.h"

namespace sfc {

std::unique_ptr<const SurfaceKind> MakeMeshKind();

}  // namespace sfc

#endif  // SFCSAMPLER_KINDS_MESH_MESH_KIND_H_
