// Built with -mavx512f -ffp-contract=off (core/CMakeLists.txt): the superellipsoid's
// batch points (core/superellipsoid_lanes.h) for AVX-512F (eight lanes, the kAvx512 path).
#include "core/superellipsoid_lanes.h"

namespace sfc::superellipsoid_internal {

size_t PointsAvx512(Shape shape, const double* u, const double* v, size_t n, double* x, double* y,
                    double* z) {
  return PointsLanes(shape, u, v, n, x, y, z);
}

}  // namespace sfc::superellipsoid_internal
