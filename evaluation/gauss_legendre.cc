#include "evaluation/gauss_legendre.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <memory>

#include "absl/synchronization/mutex.h"

namespace sfc {
namespace {

constexpr double kPi = 3.14159265358979323846;

GaussRule Compute(int n) {
  GaussRule r;
  r.x.resize(n);
  r.w.resize(n);
  for (int i = 0; i < n; ++i) {
    double z = std::cos(kPi * (i + 0.75) / (n + 0.5)), dp = 1;
    for (int it = 0; it < 100; ++it) {
      double p0 = 1, p1 = z;
      for (int k = 2; k <= n; ++k) {
        const double p2 = ((2 * k - 1) * z * p1 - (k - 1) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      if (n == 1) p0 = 1, p1 = z;
      dp = n * (z * p1 - p0) / (z * z - 1);
      const double step = p1 / dp;
      z -= step;
      if (std::fabs(step) < 1e-16) break;
    }
    r.x[i] = (1 - z) / 2;  // z descends with i, so x ascends
    r.w[i] = 1 / ((1 - z * z) * dp * dp);  // 2 / ((1-z^2) P'^2), halved for [0,1]
  }
  return r;
}

}  // namespace

const GaussRule& GaussLegendreRule(int n) {
  assert(n >= 1 && n <= 128);
  static absl::Mutex mu(absl::kConstInit);
  static std::unique_ptr<GaussRule> rules[129] ABSL_GUARDED_BY(mu);
  absl::MutexLock lock(&mu);
  if (!rules[n]) rules[n] = std::make_unique<GaussRule>(Compute(n));
  return *rules[n];
}

}  // namespace sfc
