// A subdivided icosahedron with its vertices on the unit sphere: the test and
// benchmark fixture (20 * 4^s triangles: s = 6 gives 81 920).
//
// Thread-safety: thread-safe (a pure function).
#ifndef SFCSAMPLER_MESH_ICOSPHERE_H_
#define SFCSAMPLER_MESH_ICOSPHERE_H_

#include "mesh/triangle_mesh.h"

namespace sfc {

// Each subdivision splits every triangle into four at its edge midpoints,
// which are then pushed to the unit sphere. Triangles face outwards; vertex
// normals are the positions when `with_normals`. REQUIRES: 0 <= subdivisions <= 9.
TriangleMesh MakeIcosphere(int subdivisions, bool with_normals = false);

}  // namespace sfc

#endif  // SFCSAMPLER_MESH_ICOSPHERE_H_
