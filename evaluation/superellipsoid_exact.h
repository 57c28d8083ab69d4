// Exact integrals on the superellipsoid |x|^(2/e) + |y|^(2/e) + |z|^(2/e) = 1
// (paper Sect. 5.3), written from the angles alone and sharing no code with
// core/ (not even the Surface class): the area element in the angles
// (a = latitude in [-pi/2, pi/2], b = longitude in [-pi, pi]) in closed form,
// integrated over one octant by a product Gauss-Legendre rule after the
// substitution angle = end + c w^12 toward each end of [0, pi/2]. Near a zero
// of sin or cos the area element behaves like |t|^(e-1); after the
// substitution it is w^(12 e - 1) times a smooth factor, a polynomial for
// e = 1/3, 1/4, 1/2, 1/6, 2, 3 (issue 19's t = w^3, generalised).
//
// This is the independent reference for the strip check and the Monte Carlo
// check of issue 19 and for tests of the graded box measure.
//
// Thread-safety: pure functions.
#ifndef SFCSAMPLER_EVALUATION_SUPERELLIPSOID_EXACT_H_
#define SFCSAMPLER_EVALUATION_SUPERELLIPSOID_EXACT_H_

#include <functional>

namespace sfc {

// dA / (da db) at angles a, b in [0, pi/2] (the first octant; the others are
// mirror images). Infinite on a = 0 or b = 0, 0 or pi/2 when e < 1.
double SuperellipsoidAreaElement(double e, double a, double b);

// int over a in [a0, a1], b in [b0, b1] (a sub-box of the first octant
// [0, pi/2]^2) of g(cos a, cos b) dA (g = 1 when empty). Ends at 0 and pi/2 are graded as described
// above; other ends are plain. REQUIRES: e > 0, 0 <= a0 < a1 <= pi/2, same for b.
double SuperellipsoidOctantIntegral(double e, double a0, double a1, double b0, double b1,
                                    const std::function<double(double ca, double cb)>& g = nullptr);

// Total area (8 octants). e = 1 gives 4 pi.
double SuperellipsoidArea(double e);

// The fraction of the area whose unit-parameter distance to a singular line
// is below d (d <= 1/8). Longitude lines b in {-pi, -pi/2, 0, pi/2} (unit
// distance = |b - line| / 2 pi, all four together), the equator a = 0
// (distance |a| / pi) and the two poles a = +-pi/2 together.
double SuperellipsoidLongitudeStripFraction(double e, double d);
double SuperellipsoidEquatorStripFraction(double e, double d);
double SuperellipsoidPoleStripFraction(double e, double d);

// The surface mean of x^2 (uniform density).
double SuperellipsoidMeanX2(double e);

// The longitude b and latitude a of a point on the surface, from its
// coordinates: b = atan2(s(y), s(x)), a = atan2(s(z), (|x|^(2/e) + |y|^(2/e))^(1/2))
// with s(c) = sign(c) |c|^(1/e). Exact for any parameterisation of it.
double SuperellipsoidLongitude(double e, double x, double y);
double SuperellipsoidLatitude(double e, double x, double y, double z);

}  // namespace sfc

#endif  // SFCSAMPLER_EVALUATION_SUPERELLIPSOID_EXACT_H_
