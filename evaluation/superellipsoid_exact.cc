#include "evaluation/superellipsoid_exact.h"

#include <cmath>
#include <vector>

#include "evaluation/gauss_legendre.h"

namespace sfc {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kHalfPi = kPi / 2;
constexpr int kPower = 12;   // the substitution's power
constexpr int kNodes = 40;   // Gauss-Legendre nodes per panel
constexpr int kPanels = 4;   // equal panels in w per graded piece

// An angle kept as its cosine and sine: a node at pi/2 - 1e-30 must keep
// cos = 1e-30 (pi/2 - 1e-30 itself rounds to pi/2).
struct Node {
  double c, s, w;
};

// Nodes and weights on [x0, x1], graded toward an end that is 0 or pi/2.
// A piece with both ends singular is split at its middle.
void AxisNodes(double x0, double x1, std::vector<Node>* out) {
  const bool sing0 = x0 == 0 || x0 == kHalfPi, sing1 = x1 == 0 || x1 == kHalfPi;
  if (sing0 && sing1) {
    const double mid = 0.5 * (x0 + x1);
    AxisNodes(x0, mid, out);
    AxisNodes(mid, x1, out);
    return;
  }
  const GaussRule& g = GaussLegendreRule(kNodes);
  for (int p = 0; p < kPanels; ++p) {
    for (int k = 0; k < kNodes; ++k) {
      const double w = (p + g.x[k]) / kPanels, ww = g.w[k] / kPanels;
      if (sing0 || sing1) {
        // x = end + (other - end) w^m: dx = m w^(m-1) |other - end| dw.
        const double end = sing0 ? x0 : x1, other = sing0 ? x1 : x0;
        const double wm1 = std::pow(w, kPower - 1);
        const double t = std::fabs(other - end) * wm1 * w;  // distance from `end`
        const double weight = ww * kPower * wm1 * std::fabs(other - end);
        if (end == 0) {
          out->push_back({std::cos(t), std::sin(t), weight});
        } else {  // end = pi/2: cos(pi/2 - t) = sin t
          out->push_back({std::sin(t), std::cos(t), weight});
        }
      } else {
        const double x = x0 + (x1 - x0) * w;
        out->push_back({std::cos(x), std::sin(x), ww * (x1 - x0)});
      }
    }
  }
}

double SignedRoot(double c, double e) { return std::copysign(std::pow(std::fabs(c), 1 / e), c); }


double AreaElementCS(double e, double ca, double sa, double cb, double sb) {
  // f = (C(a) C(b), C(a) S(b), S(a)) with C = cos^e, S = sin^e. In the first
  // octant C' = -e c^(e-1) s and S' = e s^(e-1) c, and
  // |f_a x f_b| = C(a) sqrt(S'(a)^2 (S'(b)^2 + C'(b)^2) + C'(a)^2 (C S' - S C')(b)^2)
  // with C S' - S C' = e (c s)^(e-1) (c^2 + s^2).
  const double dSa = e * std::pow(sa, e - 1) * ca, dCa = e * std::pow(ca, e - 1) * sa;
  const double dSb = e * std::pow(sb, e - 1) * cb, dCb = e * std::pow(cb, e - 1) * sb;
  const double wronskian = e * std::pow(cb * sb, e - 1);
  return std::pow(ca, e) *
         std::sqrt(dSa * dSa * (dSb * dSb + dCb * dCb) + dCa * dCa * wronskian * wronskian);
}

}  // namespace

double SuperellipsoidAreaElement(double e, double a, double b) {
  return AreaElementCS(e, std::cos(a), std::sin(a), std::cos(b), std::sin(b));
}

double SuperellipsoidOctantIntegral(double e, double a0, double a1, double b0, double b1,
                                    const std::function<double(double, double)>& g) {
  std::vector<Node> as, bs;
  AxisNodes(a0, a1, &as);
  AxisNodes(b0, b1, &bs);
  double sum = 0;
  for (const Node& na : as) {
    double row = 0;
    for (const Node& nb : bs) {
      const double m = AreaElementCS(e, na.c, na.s, nb.c, nb.s);
      row += nb.w * (g ? m * g(na.c, nb.c) : m);
    }
    sum += na.w * row;
  }
  return sum;
}

double SuperellipsoidArea(double e) {
  return 8 * SuperellipsoidOctantIntegral(e, 0, kHalfPi, 0, kHalfPi);
}

double SuperellipsoidLongitudeStripFraction(double e, double d) {
  // 4 lines x 2 sides x 2 latitude halves = 16 octant strips of 8 octants.
  const double strip = SuperellipsoidOctantIntegral(e, 0, kHalfPi, 0, 2 * kPi * d);
  return 2 * strip / SuperellipsoidOctantIntegral(e, 0, kHalfPi, 0, kHalfPi);
}

double SuperellipsoidEquatorStripFraction(double e, double d) {
  return SuperellipsoidOctantIntegral(e, 0, kPi * d, 0, kHalfPi) /
         SuperellipsoidOctantIntegral(e, 0, kHalfPi, 0, kHalfPi);
}

double SuperellipsoidPoleStripFraction(double e, double d) {
  return SuperellipsoidOctantIntegral(e, kHalfPi - kPi * d, kHalfPi, 0, kHalfPi) /
         SuperellipsoidOctantIntegral(e, 0, kHalfPi, 0, kHalfPi);
}

double SuperellipsoidMeanX2(double e) {
  const double x2 = SuperellipsoidOctantIntegral(
      e, 0, kHalfPi, 0, kHalfPi,
      [e](double ca, double cb) { return std::pow(ca, 2 * e) * std::pow(cb, 2 * e); });
  return x2 / SuperellipsoidOctantIntegral(e, 0, kHalfPi, 0, kHalfPi);
}

double SuperellipsoidLongitude(double e, double x, double y) {
  return std::atan2(SignedRoot(y, e), SignedRoot(x, e));
}

double SuperellipsoidLatitude(double e, double x, double y, double z) {
  return std::atan2(SignedRoot(z, e),
                    std::hypot(std::pow(std::fabs(x), 1 / e), std::pow(std::fabs(y), 1 / e)));
}

}  // namespace sfc
