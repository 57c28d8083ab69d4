// Built with -O3 -mavx2 -ffp-contract=off -fno-math-errno
// (mesh/CMakeLists.txt): the mesh warp's batch loops (mesh/mesh_warp_lanes.h)
// for AVX2; IEEE operations only, so their bits are the scalar code's.
#include "mesh/mesh_warp_lanes.h"

namespace sfc::mesh_warp_lanes {

void PathsOfAvx2(size_t n, const double* pa, const double* pb, uint64_t* paths) {
  PathsOfLanes(n, pa, pb, paths);
}

void LeafSharesAvx2(const LeafTables& tables, size_t n, const double* a, const double* b,
                    int64_t* leaf, double* f, double* g, int64_t* across) {
  LeafSharesOf(tables, n, a, b, leaf, f, g, across);
}

void PlaceUniformAvx2(size_t n, const double* f, const double* g, double* pa, double* pb) {
  PlaceUniformOf(n, f, g, pa, pb);
}

}  // namespace sfc::mesh_warp_lanes
