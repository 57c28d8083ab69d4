#include "core/builtin_surfaces.h"

#include <algorithm>
#include <cmath>

#include "core/superellipsoid_internal.h"
#include "core/vector_math.h"

namespace sfc {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Interval helpers for the Bound methods. Each Bound repeats its Point's
// operations in the same order on intervals (core/interval.h), so the box
// holds every point Point computes on the rectangle.
Interval Pt(double x) { return Interval::Point(x); }
Interval Range(double lo, double hi) { return Interval::Of(lo, hi); }

// Points in chunks: sin and cos of pi a[i] and pi b[i] (the scaled
// parameters) by the vector path, then `combine`(i, sa, ca, sb, cb) per
// point, which must do what the surface's Point does with SinCosPi's values.
template <typename Scale, typename Combine>
void SinCosPoints(const double* u, const double* v, size_t n, Scale scale_u, Scale scale_v,
                  Combine combine) {
  constexpr size_t kChunk = 256;
  double a[kChunk], b[kChunk], sa[kChunk], ca[kChunk], sb[kChunk], cb[kChunk];
  for (size_t at = 0; at < n; at += kChunk) {
    const size_t m = std::min(kChunk, n - at);
    for (size_t i = 0; i < m; ++i) a[i] = scale_u(u[at + i]), b[i] = scale_v(v[at + i]);
    math::SinCosPi(a, m, sa, ca);
    math::SinCosPi(b, m, sb, cb);
    for (size_t i = 0; i < m; ++i) combine(at + i, sa[i], ca[i], sb[i], cb[i]);
  }
}
double Same(double x) { return x; }
double Twice(double x) { return 2 * x; }

// A jet grid of a surface whose jet needs sin and cos of pi scale_u(u) and
// pi scale_v(v): each row's and column's once, in one batch call
// (math::SinCosPi's values, the same as point by point), then
// jet(s_u, c_u, s_v, c_v, &out[i * nv + j]) in place. Grids wider than 16
// take each node's values one by one (the same values).
template <typename Scale, typename Jet>
void SinCosGrid(const double* us, int nu, Scale scale_u, const double* vs, int nv, Scale scale_v,
                SurfaceJet* out, Jet jet) {
  constexpr int kMax = 16;
  double x[2 * kMax], s[2 * kMax], c[2 * kMax];  // the u's, then the v's: one batch
  if (nu > kMax || nv > kMax) {
    for (int i = 0; i < nu; ++i) {
      for (int j = 0; j < nv; ++j) {
        const math::SinCos p = math::SinCosPi(scale_u(us[i])), q = math::SinCosPi(scale_v(vs[j]));
        jet(p.sin, p.cos, q.sin, q.cos, &out[i * nv + j]);
      }
    }
    return;
  }
  for (int i = 0; i < nu; ++i) x[i] = scale_u(us[i]);
  for (int j = 0; j < nv; ++j) x[nu + j] = scale_v(vs[j]);
  math::SinCosPi(x, nu + nv, s, c);
  for (int i = 0; i < nu; ++i) {
    for (int j = 0; j < nv; ++j) jet(s[i], c[i], s[nu + j], c[nu + j], &out[i * nv + j]);
  }
}

class Plane final : public Surface {
 public:
  void Points(const double* u, const double* v, size_t n, double* x, double* y,
              double* z) const override {
    PointsOf(*this, u, v, n, x, y, z);
  }
  Vec3 Point(double u, double v) const override { return {u, v, 0}; }
  std::optional<Box3> Bound(double u0, double u1, double v0, double v1) const override {
    return Box3{{u0, v0, 0}, {u1, v1, 0}};
  }
  SurfaceJet Jet(double u, double v, int) const override {
    SurfaceJet j;
    j.p = {u, v, 0};
    j.fu = {1, 0, 0};
    j.fv = {0, 1, 0};
    return j;
  }
};

class Sphere final : public Surface {
 public:
  // theta = pi u, phi = 2 pi v.
  void Points(const double* u, const double* v, size_t n, double* x, double* y,
              double* z) const override {
    SinCosPoints(u, v, n, Same, Twice, [&](size_t i, double st, double ct, double sp, double cp) {
      x[i] = r_ * st * cp, y[i] = r_ * st * sp, z[i] = r_ * ct;
    });
  }
  explicit Sphere(double r) : r_(r) {}
  Vec3 Point(double u, double v) const override {
    const math::SinCos t = math::SinCosPi(u), p = math::SinCosPi(2 * v);
    return {r_ * t.sin * p.cos, r_ * t.sin * p.sin, r_ * t.cos};
  }
  std::optional<Box3> Bound(double u0, double u1, double v0, double v1) const override {
    const Interval a = Pt(kPi) * Range(u0, u1), b = Pt(2 * kPi) * Range(v0, v1);
    const Interval st = Sin(a), ct = Cos(a), sp = Sin(b), cp = Cos(b);
    return BoxOf(Pt(r_) * st * cp, Pt(r_) * st * sp, Pt(r_) * ct);
  }
  SurfaceJet Jet(double u, double v, int order) const override {
    const math::SinCos t = math::SinCosPi(u), p = math::SinCosPi(2 * v);
    SurfaceJet j;
    JetFrom(t.sin, t.cos, p.sin, p.cos, order, &j);
    return j;
  }
  void JetGrid(const double* us, int nu, const double* vs, int nv, int order,
               SurfaceJet* out) const override {
    SinCosGrid(us, nu, Same, vs, nv, Twice, out,
               [&](double st, double ct, double sp, double cp, SurfaceJet* j) {
                 JetFrom(st, ct, sp, cp, order, j);
               });
  }

 private:
  // The jet from sin and cos of theta = pi u and phi = 2 pi v, into `j`
  // (every field).
  void JetFrom(double st, double ct, double sp, double cp, int order, SurfaceJet* j) const {
    j->p = {r_ * st * cp, r_ * st * sp, r_ * ct};
    j->fu = Vec3{ct * cp, ct * sp, -st} * (kPi * r_);
    j->fv = Vec3{-st * sp, st * cp, 0} * (2 * kPi * r_);
    if (order >= 2) {
      j->fuu = j->p * (-kPi * kPi);
      j->fuv = Vec3{-ct * sp, ct * cp, 0} * (2 * kPi * kPi * r_);
      j->fvv = Vec3{st * cp, st * sp, 0} * (-4 * kPi * kPi * r_);
    } else {
      j->fuu = j->fuv = j->fvv = Vec3{};
    }
  }

  const double r_;
};

class Torus final : public Surface {
 public:
  // a = 2 pi u, b = 2 pi v.
  void Points(const double* u, const double* v, size_t n, double* x, double* y,
              double* z) const override {
    SinCosPoints(u, v, n, Twice, Twice, [&](size_t i, double sa, double ca, double sb, double cb) {
      const double w = big_r_ + r_ * cb;
      x[i] = w * ca, y[i] = w * sa, z[i] = r_ * sb;
    });
  }
  Torus(double big_r, double r) : big_r_(big_r), r_(r) {}
  Vec3 Point(double u, double v) const override {
    const math::SinCos a = math::SinCosPi(2 * u), b = math::SinCosPi(2 * v);
    const double w = big_r_ + r_ * b.cos;
    return {w * a.cos, w * a.sin, r_ * b.sin};
  }
  std::optional<Box3> Bound(double u0, double u1, double v0, double v1) const override {
    const Interval a = Pt(2 * kPi) * Range(u0, u1), b = Pt(2 * kPi) * Range(v0, v1);
    const Interval w = Pt(big_r_) + Pt(r_) * Cos(b);
    return BoxOf(w * Cos(a), w * Sin(a), Pt(r_) * Sin(b));
  }
  SurfaceJet Jet(double u, double v, int order) const override {
    const math::SinCos a = math::SinCosPi(2 * u), b = math::SinCosPi(2 * v);
    SurfaceJet j;
    JetFrom(a.sin, a.cos, b.sin, b.cos, order, &j);
    return j;
  }
  void JetGrid(const double* us, int nu, const double* vs, int nv, int order,
               SurfaceJet* out) const override {
    SinCosGrid(us, nu, Twice, vs, nv, Twice, out,
               [&](double sa, double ca, double sb, double cb, SurfaceJet* j) {
                 JetFrom(sa, ca, sb, cb, order, j);
               });
  }

 private:
  // The jet from sin and cos of a = 2 pi u and b = 2 pi v, into `j` (every
  // field).
  void JetFrom(double sa, double ca, double sb, double cb, int order, SurfaceJet* j) const {
    const double w = big_r_ + r_ * cb;
    const double k = 2 * kPi;
    j->p = {w * ca, w * sa, r_ * sb};
    j->fu = Vec3{-w * sa, w * ca, 0} * k;
    j->fv = Vec3{-r_ * sb * ca, -r_ * sb * sa, r_ * cb} * k;
    if (order >= 2) {
      j->fuu = Vec3{-w * ca, -w * sa, 0} * (k * k);
      j->fuv = Vec3{r_ * sb * sa, -r_ * sb * ca, 0} * (k * k);
      j->fvv = Vec3{-r_ * cb * ca, -r_ * cb * sa, -r_ * sb} * (k * k);
    } else {
      j->fuu = j->fuv = j->fvv = Vec3{};
    }
  }

  const double big_r_, r_;
};

class MonkeySaddle final : public Surface {
 public:
  void Points(const double* u, const double* v, size_t n, double* x, double* y,
              double* z) const override {
    PointsOf(*this, u, v, n, x, y, z);
  }
  Vec3 Point(double u, double v) const override {
    const double s = 2 * u - 1, t = 2 * v - 1;
    return {s, t, s * s * s - 3 * s * t * t};
  }
  std::optional<Box3> Bound(double u0, double u1, double v0, double v1) const override {
    const Interval s = Pt(2) * Range(u0, u1) - Pt(1), t = Pt(2) * Range(v0, v1) - Pt(1);
    // s * s * s is (s * s) * s: Cube; 3 * s * t * t is ((3 * s) * t) * t.
    return BoxOf(s, t, Cube(s) - Pt(3) * s * t * t);
  }
  SurfaceJet Jet(double u, double v, int order) const override {
    const double s = 2 * u - 1, t = 2 * v - 1;
    SurfaceJet j;
    j.p = {s, t, s * s * s - 3 * s * t * t};
    j.fu = {2, 0, 2 * (3 * s * s - 3 * t * t)};
    j.fv = {0, 2, 2 * (-6 * s * t)};
    if (order >= 2) {
      j.fuu = {0, 0, 4 * 6 * s};
      j.fuv = {0, 0, 4 * -6 * t};
      j.fvv = {0, 0, 4 * -6 * s};
    }
    return j;
  }
};

class EightSurface final : public Surface {
 public:
  // sin and cos of 2 pi u and 2 pi v by the vector path, then of pi v for z:
  // the values Point takes one by one.
  void Points(const double* u, const double* v, size_t n, double* x, double* y,
              double* z) const override {
    SinCosPoints(u, v, n, Twice, Twice, [&](size_t i, double sa, double ca, double s2v, double) {
      x[i] = ca * -s2v, y[i] = sa * -s2v;
    });
    constexpr size_t kChunk = 256;
    double sv[kChunk];
    for (size_t at = 0; at < n; at += kChunk) {
      const size_t m = std::min(kChunk, n - at);
      math::SinCosPi(v + at, m, sv, z + at);
      for (size_t i = at; i < at + m; ++i) z[i] = -z[i];
    }
  }
  // a = 2 pi u, b = pi v - pi/2: sin b = -cos(pi v), cos b = sin(pi v),
  // sin 2b = -sin(2 pi v), cos 2b = -cos(2 pi v).
  Vec3 Point(double u, double v) const override {
    const math::SinCos a = math::SinCosPi(2 * u), b2 = math::SinCosPi(2 * v);
    const double s2b = -b2.sin;
    return {a.cos * s2b, a.sin * s2b, -math::SinCosPi(v).cos};
  }
  std::optional<Box3> Bound(double u0, double u1, double v0, double v1) const override {
    const Interval a = Pt(2 * kPi) * Range(u0, u1), b = Pt(kPi) * Range(v0, v1) - Pt(kPi / 2);
    const Interval s2b = Sin(Pt(2) * b);
    return BoxOf(Cos(a) * s2b, Sin(a) * s2b, Sin(b));
  }
  SurfaceJet Jet(double u, double v, int order) const override {
    const math::SinCos a = math::SinCosPi(2 * u), b = math::SinCosPi(v), b2 = math::SinCosPi(2 * v);
    SurfaceJet j;
    JetFrom(a, b, b2, order, &j);
    return j;
  }
  // Each row's and column's sines and cosines once, in one batch call (the
  // values Jet takes node by node); grids wider than 16 node by node.
  void JetGrid(const double* us, int nu, const double* vs, int nv, int order,
               SurfaceJet* out) const override {
    constexpr int kMax = 16;
    if (nu > kMax || nv > kMax) {
      Surface::JetGrid(us, nu, vs, nv, order, out);
      return;
    }
    double x[3 * kMax], s[3 * kMax], c[3 * kMax];  // 2u's, v's, 2v's
    for (int i = 0; i < nu; ++i) x[i] = 2 * us[i];
    for (int j = 0; j < nv; ++j) x[nu + j] = vs[j], x[nu + nv + j] = 2 * vs[j];
    math::SinCosPi(x, nu + 2 * nv, s, c);
    for (int i = 0; i < nu; ++i) {
      for (int j = 0; j < nv; ++j) {
        const int b = nu + j, b2 = nu + nv + j;
        JetFrom({s[i], c[i]}, {s[b], c[b]}, {s[b2], c[b2]}, order, &out[i * nv + j]);
      }
    }
  }

 private:
  // The jet from sin and cos of pi (2u), pi v and pi (2v), into `j` (every
  // field).
  static void JetFrom(math::SinCos a, math::SinCos b, math::SinCos b2, int order, SurfaceJet* j) {
    const double sa = a.sin, ca = a.cos;
    const double s2b = -b2.sin, c2b = -b2.cos;
    const double sb = -b.cos, cb = b.sin;
    j->p = {ca * s2b, sa * s2b, sb};
    j->fu = Vec3{-sa * s2b, ca * s2b, 0} * (2 * kPi);
    j->fv = Vec3{2 * ca * c2b, 2 * sa * c2b, cb} * kPi;
    if (order >= 2) {
      j->fuu = Vec3{-ca * s2b, -sa * s2b, 0} * (4 * kPi * kPi);
      j->fuv = Vec3{-2 * sa * c2b, 2 * ca * c2b, 0} * (2 * kPi * kPi);
      j->fvv = Vec3{-4 * ca * s2b, -4 * sa * s2b, -sb} * (kPi * kPi);
    } else {
      j->fuu = j->fuv = j->fvv = Vec3{};
    }
  }
};

class WhitneyUmbrella final : public Surface {
 public:
  void Points(const double* u, const double* v, size_t n, double* x, double* y,
              double* z) const override {
    PointsOf(*this, u, v, n, x, y, z);
  }
  Vec3 Point(double u, double v) const override {
    const double s = 2 * u - 1, t = 2 * v - 1;
    return {s * t, s, t * t};
  }
  std::optional<Box3> Bound(double u0, double u1, double v0, double v1) const override {
    const Interval s = Pt(2) * Range(u0, u1) - Pt(1), t = Pt(2) * Range(v0, v1) - Pt(1);
    return BoxOf(s * t, s, Square(t));
  }
  SurfaceJet Jet(double u, double v, int order) const override {
    const double s = 2 * u - 1, t = 2 * v - 1;
    SurfaceJet j;
    j.p = {s * t, s, t * t};
    j.fu = {2 * t, 2, 0};
    j.fv = {2 * s, 0, 4 * t};
    if (order >= 2) j.fuv = {4, 0, 0}, j.fvv = {0, 0, 8};
    return j;
  }
};

// Signed power sign(c)|c|^e.
// std::round's value without its library call (x86-64's baseline has no
// rounding instruction): the integer part by conversion, exact below 2^52,
// then halves away from zero; the sign of a zero kept.
double RoundHalfAway(double y) {
  if (!(std::fabs(y) < 0x1p52)) return std::round(y);  // an integer already, or NaN
  const double t = std::copysign(static_cast<double>(static_cast<int64_t>(y)), y);
  return std::fabs(y - t) >= 0.5 ? t + std::copysign(1.0, y) : t;
}

// a^e for a >= 0, the superellipsoid's powers of |cos| and |sin| (points,
// bounds and the value of its jets alike): the cube root where e is the
// double nearest 1/3, the default exponent, three times as fast as Pow.
double Power(double a, double e) { return e == 1.0 / 3 ? math::Cbrt(a) : math::Pow(a, e); }
// Power(a[i], e) for a[0..n) into out[i], bit for bit.
void Powers(const double* a, double e, size_t n, double* out) {
  e == 1.0 / 3 ? math::Cbrt(a, n, out) : math::Pow(a, e, n, out);
}

double SignedPow(double c, double e) { return std::copysign(Power(std::fabs(c), e), c); }

// g(x) = sign(c(x)) |c(x)|^e for c = cos or sin, with its first two
// derivatives. With e < 1 the derivatives are infinite where c = 0 (the
// superellipsoid's singular lines, paper Sect. 5.3); callers of the jet see
// the infinity, the tree never evaluates its mass estimates there.
struct PowTrig {
  double g = 0, d1 = 0, d2 = 0;
};
// c = cos x or sin x, dc its derivative (-sin x or cos x); c'' = -c; with
// the powers of a = |c| given: pe = Power(a, e), pe1 = a^(e-1) (read when
// e != 1) and pe2 = a^(e-2) (when e != 1 and order >= 2), math::Pow's values.
PowTrig SignedPowFrom(double c, double dc, double e, int order, double pe, double pe1,
                      double pe2) {
  PowTrig r;
  r.g = std::copysign(pe, c);
  // d/dx sign(c)|c|^e = e |c|^(e-1) c'
  r.d1 = e == 1 ? dc : e * pe1 * dc;
  if (order >= 2) {
    // d2 = e (e-1) |c|^(e-2) sign(c) c'^2 + e |c|^(e-1) c''
    const double curv = e == 1 ? 0 : e * (e - 1) * std::copysign(pe2, c) * dc * dc;
    r.d2 = curv + (e == 1 ? -c : -e * pe1 * c);
  }
  return r;
}
PowTrig SignedPowOf(double c, double dc, double e, int order) {
  const double a = std::fabs(c);
  const bool more = e != 1;
  return SignedPowFrom(c, dc, e, order, Power(a, e), more ? math::Pow(a, e - 1) : 0,
                       more && order >= 2 ? math::Pow(a, e - 2) : 0);
}

class Superellipsoid final : public Surface {
 public:
  // On the AVX2 and AVX-512F paths, whole blocks of points in vectors
  // (core/superellipsoid_lanes.h); on the others, and for a tail or a block
  // with parameters outside [0, 1], PointsInChunks. The same bits.
  void Points(const double* u, const double* v, size_t n, double* x, double* y,
              double* z) const override {
    static const math::VectorPath path = math::BestVectorPath();
    const superellipsoid_internal::Shape shape{e_, reparam_};
    constexpr size_t kBlock = superellipsoid_internal::kBlock;
    size_t i = 0;
    while (path == math::VectorPath::kAvx512 || path == math::VectorPath::kAvx2) {
      i += path == math::VectorPath::kAvx512
               ? superellipsoid_internal::PointsAvx512(shape, u + i, v + i, n - i, x + i, y + i,
                                                       z + i)
               : superellipsoid_internal::PointsAvx2(shape, u + i, v + i, n - i, x + i, y + i,
                                                     z + i);
      if (n - i < kBlock) break;
      PointsInChunks(u + i, v + i, kBlock, x + i, y + i, z + i);  // a parameter outside [0, 1]
      i += kBlock;
    }
    PointsInChunks(u + i, v + i, n - i, x + i, y + i, z + i);
  }
  // Point's operations in chunks: the angles' sin and cos, then the four
  // powers of each point, in batch calls of the vector path (the same bits).
  void PointsInChunks(const double* u, const double* v, size_t n, double* x, double* y,
                      double* z) const {
    constexpr size_t kChunk = 256;
    int quarter[2 * kChunk];
    double offset[2 * kChunk], s[2 * kChunk], c[2 * kChunk], base[4 * kChunk], g[4 * kChunk];
    for (size_t at = 0; at < n; at += kChunk) {
      const size_t m = std::min(kChunk, n - at);
      for (size_t i = 0; i < m; ++i) {
        const AngleJet a = Angle(u[at + i], -1, 2), b = Angle(v[at + i], -2, 4);
        quarter[i] = a.quarter, offset[i] = a.offset;
        quarter[m + i] = b.quarter, offset[m + i] = b.offset;
      }
      math::SinCosOf(offset, 2 * m, s, c);
      // base: |cos a|, |sin a| of the u angles, then of the v angles.
      for (size_t i = 0; i < 2 * m; ++i) {
        Turn(quarter[i], c[i], s[i], &c[i], &s[i]);
        base[2 * i] = std::fabs(c[i]), base[2 * i + 1] = std::fabs(s[i]);
      }
      Powers(base, e_, 4 * m, g);
      for (size_t i = 0; i < m; ++i) {
        const double ca = std::copysign(g[2 * i], c[i]), sa = std::copysign(g[2 * i + 1], s[i]);
        const double cb = std::copysign(g[2 * (m + i)], c[m + i]);
        const double sb = std::copysign(g[2 * (m + i) + 1], s[m + i]);
        x[at + i] = ca * cb, y[at + i] = ca * sb, z[at + i] = sa;
      }
    }
  }
  Superellipsoid(double e, bool reparam) : e_(e), reparam_(reparam) {}
  Vec3 Point(double u, double v) const override {
    double ca, sa, cb, sb;
    Angle(u, -1, 2).CosSin(&ca, &sa);
    Angle(v, -2, 4).CosSin(&cb, &sb);
    ca = SignedPow(ca, e_), sa = SignedPow(sa, e_), cb = SignedPow(cb, e_), sb = SignedPow(sb, e_);
    return {ca * cb, ca * sb, sa};
  }
  std::optional<Box3> Bound(double u0, double u1, double v0, double v1) const override {
    const Interval a = AngleBound(u0, u1, -kPi / 2, 2), b = AngleBound(v0, v1, -kPi, 4);
    const Interval ca = SignedPowBound(Cos(a)), sa = SignedPowBound(Sin(a));
    const Interval cb = SignedPowBound(Cos(b)), sb = SignedPowBound(Sin(b));
    return BoxOf(ca * cb, ca * sb, sa);
  }

  // Closed-form derivatives (chain rule through the angle maps).
  SurfaceJet Jet(double u, double v, int order) const override {
    SurfaceJet j;
    Combine(FactorsU(u, order), FactorsV(v, order), order, &j);
    return j;
  }
  void JetGrid(const double* us, int nu, const double* vs, int nv, int order,
               SurfaceJet* out) const override {
    constexpr int kMax = 16;
    if (nu > kMax || nv > kMax) return Surface::JetGrid(us, nu, vs, nv, order, out);
    // The rows' and columns' angles (u's, then v's), their sin and cos, and
    // the powers of |cos| and |sin| in batch calls (the same bits as FactorsU
    // and FactorsV one by one).
    const int n = nu + nv;
    AngleJet angle[2 * kMax];
    double offset[2 * kMax], c[2 * kMax], s[2 * kMax], base[4 * kMax];
    double pe[4 * kMax], pe1[4 * kMax] = {}, pe2[4 * kMax] = {};
    for (int i = 0; i < n; ++i) {
      angle[i] = i < nu ? Angle(us[i], -1, 2) : Angle(vs[i - nu], -2, 4);
      offset[i] = angle[i].offset;
    }
    math::SinCosOf(offset, n, s, c);
    for (int i = 0; i < n; ++i) {
      Turn(angle[i].quarter, c[i], s[i], &c[i], &s[i]);
      base[2 * i] = std::fabs(c[i]), base[2 * i + 1] = std::fabs(s[i]);
    }
    Powers(base, e_, 2 * n, pe);
    if (e_ != 1) {
      math::Pow(base, e_ - 1, 2 * n, pe1);
      if (order >= 2) math::Pow(base, e_ - 2, 2 * n, pe2);
    }
    Factors f[2 * kMax];
    for (int i = 0; i < n; ++i) {
      const int k = 2 * i, l = 2 * i + 1;
      f[i].c = SignedPowFrom(c[i], -s[i], e_, order, pe[k], pe1[k], pe2[k]);
      f[i].s = SignedPowFrom(s[i], c[i], e_, order, pe[l], pe1[l], pe2[l]);
      Chain(angle[i], &f[i]);
    }
    for (int i = 0; i < nu; ++i) {
      for (int j = 0; j < nv; ++j) Combine(f[i], f[nu + j], order, &out[i * nv + j]);
    }
  }

 private:
  // An angle quarter * pi/2 + offset (|offset| <= pi/4), kept apart so that
  // cos and sin near their zeros keep full relative precision (the angle
  // itself would round -pi + pi - 1e-20 to 0), and its first two derivatives
  // with respect to the parameter.
  struct AngleJet {
    int quarter;
    double offset, d1, d2;
    void CosSin(double* c, double* s) const {
      const math::SinCos r = math::SinCosOf(offset);
      Turn(quarter, r.cos, r.sin, c, s);
    }
  };
  // cos and sin of quarter * pi/2 + offset from co, so: those of the offset.
  static void Turn(int quarter, double co, double so, double* c, double* s) {
    switch (((quarter % 4) + 4) % 4) {
      case 0: *c = co, *s = so; break;
      case 1: *c = -so, *s = co; break;
      case 2: *c = -co, *s = -so; break;
      default: *c = so, *s = -co; break;
    }
  }
  // cos- and sin-type factors of one parameter, differentiated by it.
  struct Factors {
    PowTrig c, s;
  };

  // Maps x in [0,1] onto [start, start + pieces] quarter turns, piecewise by
  // quarter turns, with the double-ended power law q(s) = s^3 / (s^3 + (1-s)^3)
  // when reparameterising.
  AngleJet Angle(double x, int start, int pieces) const {
    const double quarter = kPi / 2;
    const double y = x * pieces;  // exact: pieces is a power of two
    if (!reparam_) {
      const double k = RoundHalfAway(y);
      return {start + static_cast<int>(k), (y - k) * quarter, pieces * quarter, 0};
    }
    const int piece = std::min(static_cast<int>(y), pieces - 1);
    const double s = y - piece, r = 1 - s;
    const double s3 = s * s * s, r3 = r * r * r, d = s3 + r3;
    // q' = 3 s^2 r^2 / d^2, q'' = (n' d - 2 n d') / d^3 with n = 3 s^2 r^2.
    const double n = 3 * s * s * r * r, dn = 6 * s * r * (r - s), dd = 3 * s * s - 3 * r * r;
    const double q1 = n / (d * d), q2 = (dn * d - 2 * n * dd) / (d * d * d);
    const double d1 = q1 * pieces * quarter, d2 = q2 * pieces * pieces * quarter;
    // Near the piece's end measure from it: 1 - q = r^3 / d without cancellation.
    if (s <= 0.5) return {start + piece, s3 / d * quarter, d1, d2};
    return {start + piece + 1, -r3 / d * quarter, d1, d2};
  }

  Factors FactorsOf(const AngleJet& a, int order) const {
    double c, s;
    a.CosSin(&c, &s);
    Factors f;
    f.c = SignedPowOf(c, -s, e_, order);
    f.s = SignedPowOf(s, c, e_, order);
    Chain(a, &f);
    return f;
  }
  // Chain rule: d/dx g(a(x)) = g' a', d2 = g'' a'^2 + g' a''.
  static void Chain(const AngleJet& a, Factors* f) {
    for (PowTrig* p : {&f->c, &f->s}) {
      p->d2 = p->d2 * a.d1 * a.d1 + (a.d2 != 0 ? p->d1 * a.d2 : 0);
      p->d1 *= a.d1;
    }
  }
  Factors FactorsU(double u, int order) const { return FactorsOf(Angle(u, -1, 2), order); }
  Factors FactorsV(double v, int order) const { return FactorsOf(Angle(v, -2, 4), order); }

  // f = (ca cb, ca sb, sa) from the u factors (ca, sa) and v factors (cb, sb).
  static void Combine(const Factors& fu, const Factors& fv, int order, SurfaceJet* j) {
    const PowTrig &ca = fu.c, &sa = fu.s, &cb = fv.c, &sb = fv.s;
    j->p = {ca.g * cb.g, ca.g * sb.g, sa.g};
    j->fu = {ca.d1 * cb.g, ca.d1 * sb.g, sa.d1};
    j->fv = {ca.g * cb.d1, ca.g * sb.d1, 0};
    if (order >= 2) {
      j->fuu = {ca.d2 * cb.g, ca.d2 * sb.g, sa.d2};
      j->fuv = {ca.d1 * cb.d1, ca.d1 * sb.d1, 0};
      j->fvv = {ca.g * cb.d2, ca.g * sb.d2, 0};
    }
  }

  // Encloses Angle(x, start, pieces) for x in [x0, x1]: Angle's operations on
  // intervals, piece by piece.
  Interval AngleBound(double x0, double x1, double start, int pieces) const {
    const Interval x = Range(x0, x1);
    if (!reparam_) return Pt(start) + x * Pt(pieces) * Pt(kPi / 2);
    const Interval y = x * Pt(pieces);
    const int first = std::clamp(static_cast<int>(y.lo), 0, pieces - 1);
    const int last = std::clamp(static_cast<int>(y.hi), 0, pieces - 1);
    Interval hull;
    for (int piece = first; piece <= last; ++piece) {
      // The y of this piece: static_cast<int>(y) == piece, or y up to pieces.
      const double hi = piece == pieces - 1 ? y.hi : std::min(y.hi, piece + 1.0);
      const Interval s = Range(std::max(y.lo, static_cast<double>(piece)), hi) - Pt(piece);
      // s^3 / (s^3 + (1-s)^3) increases with s; computed as Angle computes it.
      auto power_law = [](double t) {
        const double t3 = t * t * t, r3 = (1 - t) * (1 - t) * (1 - t);
        return t3 / (t3 + r3);
      };
      const Interval q = IncreasingImage(s, power_law(s.lo), power_law(s.hi));
      const Interval angle = Pt(start) + (Pt(piece) + q) * Pt(kPi / 2);
      hull = piece == first ? angle : Hull(hull, angle);
    }
    return hull;
  }

  // SignedPow(c, e_) for c in the interval: non-decreasing in c.
  Interval SignedPowBound(const Interval& c) const {
    return IncreasingImage(c, SignedPow(c.lo, e_), SignedPow(c.hi, e_));
  }

  const double e_;
  const bool reparam_;
};

}  // namespace

std::unique_ptr<Surface> MakePlane() { return std::make_unique<Plane>(); }
std::unique_ptr<Surface> MakeSphere(double radius) { return std::make_unique<Sphere>(radius); }
std::unique_ptr<Surface> MakeTorus(double major_radius, double minor_radius) {
  return std::make_unique<Torus>(major_radius, minor_radius);
}
std::unique_ptr<Surface> MakeMonkeySaddle() { return std::make_unique<MonkeySaddle>(); }
std::unique_ptr<Surface> MakeEightSurface() { return std::make_unique<EightSurface>(); }
std::unique_ptr<Surface> MakeWhitneyUmbrella() { return std::make_unique<WhitneyUmbrella>(); }
std::unique_ptr<Surface> MakeSuperellipsoid(double exponent, bool power_reparameterisation) {
  return std::make_unique<Superellipsoid>(exponent, power_reparameterisation);
}

}  // namespace sfc
