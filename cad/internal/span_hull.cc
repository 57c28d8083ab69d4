#include "cad/internal/span_hull.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace sfc::cad {
namespace {

// The n control points (4 doubles each, `stride` doubles apart) of a Bezier
// curve over [0, 1], replaced in place by those of the same curve over
// [0, t] (keep_left) or [t, 1]: de Casteljau's triangle, whose left edge
// P_0^0 .. P_0^(n-1) and right edge P_0^(n-1) .. P_(n-1)^0 are the halves'.
void Split(double* p, int n, int stride, double t, bool keep_left) {
  const double s = 1 - t;
  for (int r = 1; r < n; ++r) {
    if (keep_left) {
      for (int i = n - 1; i >= r; --i) {
        for (int k = 0; k < 4; ++k)
          p[i * stride + k] = s * p[(i - 1) * stride + k] + t * p[i * stride + k];
      }
    } else {
      for (int i = 0; i + r < n; ++i) {
        for (int k = 0; k < 4; ++k)
          p[i * stride + k] = s * p[i * stride + k] + t * p[(i + 1) * stride + k];
      }
    }
  }
}

// The same curve over [t0, t1] of its [0, 1]: first [0, t1], then that
// curve's [t0 / t1, 1].
void Restrict(double* p, int n, int stride, double t0, double t1) {
  if (t1 < 1) Split(p, n, stride, t1, true);
  if (t0 > 0 && t1 > 0) Split(p, n, stride, t0 / t1, false);
}

// The spans [first, last] of `knots` that [x0, x1] meets; false when it
// leaves the knots' range by more than 1e-9 of it.
bool SpansOf(const std::vector<double>& knots, double x0, double x1, int* first, int* last) {
  const double lo = knots.front(), hi = knots.back(), slack = 1e-9 * (hi - lo);
  if (!(x0 >= lo - slack && x1 <= hi + slack && x0 <= x1)) return false;
  const int spans = static_cast<int>(knots.size()) - 1;
  auto span_of = [&](double x) {
    const int s =
        static_cast<int>(std::upper_bound(knots.begin(), knots.end(), x) - knots.begin()) - 1;
    return std::clamp(s, 0, spans - 1);
  };
  *first = span_of(x0), *last = span_of(x1);
  return true;
}

}  // namespace

SpanHull::SpanHull(std::vector<double> u_knots, std::vector<double> v_knots, int pu, int pv,
                   std::vector<double> points)
    : u_knots_(std::move(u_knots)),
      v_knots_(std::move(v_knots)),
      pu_(pu),
      pv_(pv),
      points_(std::move(points)) {}

std::optional<Box3> SpanHull::Bound(double a0, double a1, double b0, double b1) const {
  int ua, ub, va, vb;
  if (!SpansOf(u_knots_, a0, a1, &ua, &ub) || !SpansOf(v_knots_, b0, b1, &va, &vb)) {
    return std::nullopt;
  }
  const int nv = static_cast<int>(v_knots_.size()) - 1, size = pu_ * pv_ * 4;
  std::vector<double> work(size);
  Vec3 lo{INFINITY, INFINITY, INFINITY}, hi{-INFINITY, -INFINITY, -INFINITY};
  // The sub-box in a span's own [0, 1], widened for the mapping's rounding.
  auto local = [](double x, double k0, double k1, double widen) {
    return std::clamp((x - k0) / (k1 - k0) + widen, 0.0, 1.0);
  };
  for (int a = ua; a <= ub; ++a) {
    const double s0 = local(a0, u_knots_[a], u_knots_[a + 1], -1e-12);
    const double s1 = local(a1, u_knots_[a], u_knots_[a + 1], 1e-12);
    for (int b = va; b <= vb; ++b) {
      const double t0 = local(b0, v_knots_[b], v_knots_[b + 1], -1e-12);
      const double t1 = local(b1, v_knots_[b], v_knots_[b + 1], 1e-12);
      const double* patch = &points_[static_cast<size_t>(a * nv + b) * size];
      std::copy(patch, patch + size, work.begin());
      for (int j = 0; j < pv_; ++j) Restrict(&work[j * 4], pu_, pv_ * 4, s0, s1);
      for (int i = 0; i < pu_; ++i) Restrict(&work[i * pv_ * 4], pv_, 4, t0, t1);
      for (int q = 0; q < pu_ * pv_; ++q) {
        const double* h = &work[q * 4];
        if (!(h[3] > 0)) return std::nullopt;
        const Vec3 p{h[0] / h[3], h[1] / h[3], h[2] / h[3]};
        lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
        hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
      }
    }
  }
  return Box3{lo, hi};
}

}  // namespace sfc::cad
