// Built with -O3 -mavx -ffp-contract=off (core/CMakeLists.txt): FollowSlopesOf
// vectorised; IEEE operations only, so its bits are the scalar code's.
#include "core/slope_batch.h"

namespace sfc::slope_batch {

void FollowSlopesAvx(double* c, const double* p, const double* q, size_t n, bool exact_inverse,
                     double cells, double inverse) {
  FollowSlopesOf(c, p, q, n, exact_inverse, cells, inverse);
}

}  // namespace sfc::slope_batch
