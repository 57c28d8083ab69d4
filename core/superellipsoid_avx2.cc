// Built with -mavx2 -ffp-contract=off (core/CMakeLists.txt): the superellipsoid's
// batch points (core/superellipsoid_lanes.h) for AVX2 (four lanes, the kAvx2 path).
#include "core/superellipsoid_lanes.h"

namespace sfc::superellipsoid_internal {

size_t PointsAvx2(Shape shape, const double* u, const double* v, size_t n, double* x, double* y,
                  double* z) {
  return PointsLanes(shape, u, v, n, x, y, z);
}

}  // namespace sfc::superellipsoid_internal
