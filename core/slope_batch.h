// The in-cell placement of LeafWalk (core/leaf_walk.h) over a run of
// samples, written so that compilers vectorise it: IEEE operations only
// (+ - * / sqrt and comparisons; the build has -ffp-contract=off), so every
// instruction set gives the scalar code's bits. slope_batch_avx.cc and
// slope_batch_avx512.cc build it for AVX and AVX-512F; FollowSlopes
// dispatches on math::BestVectorPath() (its AVX build on the AVX2 path:
// math::WithoutAvx2).
#ifndef SFCSAMPLER_CORE_SLOPE_BATCH_H_
#define SFCSAMPLER_CORE_SLOPE_BATCH_H_

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace sfc::slope_batch {

// The point at fraction f of [0, 1] under the linear density 1 + g (2s - 1)
// with g = q / p (mean 1, slope 2g; p > 0 and |q| <= p keep it >= 0): the
// root in [0, 1] of g s^2 + (1 - g) s = f, in the form without cancellation,
// times p / p so that no division by p is needed per cell. Monotone in f, 0
// at 0 and 1 at 1, and f itself for q = 0 (2fp / 2p, exact).
inline double FollowSlope(double f, double p, double q) {
  const double a = p - q;
  return std::min(2 * f * p / (a + std::sqrt(a * a + 4 * q * f * p)), 1.0);
}

// For each i < n: the centre c[i] of a continuation cell, counted in cells
// (an integer plus a half), as a fraction of its square (times `inverse`
// when `exact_inverse`, else divided by `cells`), then moved by
// FollowSlope(., p[i], q[i]); into c[i].
inline void FollowSlopesOf(double* c, const double* p, const double* q, size_t n,
                           bool exact_inverse, double cells, double inverse) {
  if (exact_inverse) {
    for (size_t i = 0; i < n; ++i) c[i] = FollowSlope(c[i] * inverse, p[i], q[i]);
  } else {
    for (size_t i = 0; i < n; ++i) c[i] = FollowSlope(c[i] / cells, p[i], q[i]);
  }
}

// FollowSlopesOf on the widest path this CPU runs (the same bits on each).
void FollowSlopes(double* c, const double* p, const double* q, size_t n, bool exact_inverse,
                  double cells, double inverse);
// The AVX and AVX-512F builds.
void FollowSlopesAvx(double* c, const double* p, const double* q, size_t n, bool exact_inverse,
                     double cells, double inverse);
void FollowSlopesAvx512(double* c, const double* p, const double* q, size_t n, bool exact_inverse,
                        double cells, double inverse);

}  // namespace sfc::slope_batch

#endif  // SFCSAMPLER_CORE_SLOPE_BATCH_H_
