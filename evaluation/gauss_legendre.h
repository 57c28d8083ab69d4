// Gauss-Legendre rules on [0, 1] for the evaluation's quadratures, computed
// once per order by Newton's method on P_n and cached.
//
// Thread-safety: thread-safe (the cache is built under a mutex; rules are
// immutable once returned).
#ifndef SFCSAMPLER_EVALUATION_GAUSS_LEGENDRE_H_
#define SFCSAMPLER_EVALUATION_GAUSS_LEGENDRE_H_

#include <vector>

namespace sfc {

struct GaussRule {
  std::vector<double> x, w;  // nodes in (0,1) ascending, weights summing to 1
};

// REQUIRES: 1 <= n <= 128.
const GaussRule& GaussLegendreRule(int n);

}  // namespace sfc

#endif  // SFCSAMPLER_EVALUATION_GAUSS_LEGENDRE_H_
