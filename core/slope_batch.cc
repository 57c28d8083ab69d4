#include "core/slope_batch.h"

#include "core/vector_math.h"

namespace sfc::slope_batch {

void FollowSlopes(double* c, const double* p, const double* q, size_t n, bool exact_inverse,
                  double cells, double inverse) {
  static const math::VectorPath path = math::WithoutAvx2(math::BestVectorPath());
  if (path == math::VectorPath::kAvx512) {
    return FollowSlopesAvx512(c, p, q, n, exact_inverse, cells, inverse);
  }
  if (path == math::VectorPath::kAvx)
    return FollowSlopesAvx(c, p, q, n, exact_inverse, cells, inverse);
  FollowSlopesOf(c, p, q, n, exact_inverse, cells, inverse);
}

}  // namespace sfc::slope_batch
