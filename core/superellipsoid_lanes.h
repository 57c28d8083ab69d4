// The superellipsoid's batch points (core/superellipsoid_internal.h) in
// generic vectors (core/vector_lanes.h), a block of points at a time: each
// lane does Superellipsoid::Point's IEEE operations in its order
// (core/builtin_surfaces.cc: Angle, Turn, the powers of |cos| and |sin| and
// their signs; selects for its branches, sign bits for fabs, copysign and
// negation; the build has -ffp-contract=off) and calls SLEEF's cinz
// functions, whose bits are the same at every width, so every instruction
// set gives the scalar reference's bits. superellipsoid_avx2.cc builds it
// for AVX2 (four lanes, with SLEEF's AVX functions) and
// superellipsoid_avx512.cc for AVX-512F (eight lanes). Internal linkage on
// purpose (an anonymous namespace): each file keeps its own copy, compiled
// for its instruction set.
//
// Thread-safety: pure functions.
#ifndef SFCSAMPLER_CORE_SUPERELLIPSOID_LANES_H_
#define SFCSAMPLER_CORE_SUPERELLIPSOID_LANES_H_

#include <immintrin.h>
#include <sleef.h>

#include <cstddef>
#include <cstdint>
#include <cstring>

#include "core/superellipsoid_internal.h"
#include "core/vector_lanes.h"

namespace sfc::superellipsoid_internal {
namespace {

using vector_lanes::Any;
using vector_lanes::Doubles;
using vector_lanes::Ints;
using vector_lanes::kLanes;
using vector_lanes::Words;

#if !defined(__AVX512F__) && !defined(__AVX2__)
#error "superellipsoid_lanes.h is built for AVX2 or AVX-512F only"
#endif

constexpr double kQuarterTurn = 3.14159265358979323846 / 2;
constexpr uint64_t kSignBit = uint64_t{1} << 63;

__attribute__((always_inline)) inline Doubles Load(const double* p) {
  Doubles r;
  std::memcpy(&r, p, sizeof r);
  return r;
}
__attribute__((always_inline)) inline void Store(Doubles x, double* p) {
  std::memcpy(p, &x, sizeof x);
}
__attribute__((always_inline)) inline Doubles Splat(double x) { return Doubles{} + x; }

// std::fabs, std::copysign and unary minus: the sign bit alone.
__attribute__((always_inline)) inline Doubles Abs(Doubles x) {
  return (Doubles)((Words)x & ~kSignBit);
}
__attribute__((always_inline)) inline Doubles CopySign(Doubles magnitude, Doubles sign) {
  return (Doubles)(((Words)magnitude & ~kSignBit) | ((Words)sign & kSignBit));
}
__attribute__((always_inline)) inline Doubles NegateWhere(Ints mask, Doubles x) {
  return (Doubles)((Words)x ^ ((Words)mask & kSignBit));
}

// x rounded by `kMode` (_MM_FROUND_TO_ZERO, _MM_FROUND_TO_NEG_INF): exact, one
// instruction (the zero-masked AVX-512F form: GCC's unmasked one warns of its
// undefined source).
template <int kMode>
__attribute__((always_inline)) inline Doubles Round(Doubles x) {
#ifdef __AVX512F__
  return (Doubles)_mm512_maskz_roundscale_pd(0xff, (__m512d)x, kMode | _MM_FROUND_NO_EXC);
#else
  return (Doubles)_mm256_round_pd((__m256d)x, kMode | _MM_FROUND_NO_EXC);
#endif
}
__attribute__((always_inline)) inline Doubles Trunc(Doubles x) {
  return Round<_MM_FROUND_TO_ZERO>(x);
}
__attribute__((always_inline)) inline Doubles Floor(Doubles x) {
  return Round<_MM_FROUND_TO_NEG_INF>(x);
}

// SLEEF's cinz functions of core/vector_math.h for this build's vectors.
__attribute__((always_inline)) inline void SinCos(Doubles x, Doubles* s, Doubles* c) {
#ifdef __AVX512F__
  const Sleef___m512d_2 r = Sleef_cinz_sincosd8_u10avx512fnofma((__m512d)x);
#else
  const Sleef___m256d_2 r = Sleef_cinz_sincosd4_u10avx((__m256d)x);
#endif
  *s = (Doubles)r.x, *c = (Doubles)r.y;
}
// Power(a, e) of core/builtin_surfaces.cc: the cube root where `cbrt`.
__attribute__((always_inline)) inline Doubles Power(Doubles a, double e, bool cbrt) {
#ifdef __AVX512F__
  return cbrt ? (Doubles)Sleef_cinz_cbrtd8_u35avx512fnofma((__m512d)a)
              : (Doubles)Sleef_cinz_powd8_u10avx512fnofma((__m512d)a, _mm512_set1_pd(e));
#else
  return cbrt ? (Doubles)Sleef_cinz_cbrtd4_u35avx((__m256d)a)
              : (Doubles)Sleef_cinz_powd4_u10avx((__m256d)a, _mm256_set1_pd(e));
#endif
}

// Superellipsoid::Angle's quarter (an integer, as a double) and offset for
// x in [0, 1]: start + `pieces` quarter turns.
struct Angles {
  Doubles quarter, offset;
};
__attribute__((always_inline)) inline Angles AngleOf(Doubles x, double start, double pieces,
                                                     bool reparam) {
  const Doubles y = x * pieces;
  if (!reparam) {
    // RoundHalfAway: the integer part with y's sign, then halves away from zero.
    const Doubles t = CopySign(Trunc(y), y);
    const Doubles k = Abs(y - t) >= 0.5 ? t + CopySign(Splat(1.0), y) : t;
    return {start + k, (y - k) * kQuarterTurn};
  }
  // static_cast<int>(y) as a double: + 0 turns a -0 into the int's +0.
  const Doubles last = Splat(pieces - 1), truncated = Trunc(y) + 0.0;
  const Doubles piece = truncated < last ? truncated : last;
  const Doubles s = y - piece, r = 1 - s;
  const Doubles s3 = s * s * s, r3 = r * r * r, d = s3 + r3;
  const Ints low = s <= 0.5;
  return {low ? start + piece : start + piece + 1, (low ? s3 : -r3) / d * kQuarterTurn};
}

// cos and sin of an angle: Superellipsoid::Turn from those of its offset.
__attribute__((always_inline)) inline void CosSin(const Angles& a, Doubles* c, Doubles* s) {
  Doubles so, co;
  SinCos(a.offset, &so, &co);
  // The quarter modulo 4, exact: quarter - 4 floor(quarter / 4).
  const Doubles q = a.quarter - 4 * Floor(a.quarter * 0.25);
  const Ints odd = (q == 1) | (q == 3);
  *c = NegateWhere((q == 1) | (q == 2), odd ? so : co);
  *s = NegateWhere(q >= 2, odd ? co : so);
}

// Points a block at a time, in three passes over its vectors: the angles'
// cos and sin, then the powers of their magnitudes, then the signs and
// products. Each pass's calls are independent of one another, so the core
// overlaps them; one vector's chain of calls at a time waited on each.

__attribute__((always_inline)) inline size_t PointsLanes(Shape shape, const double* u,
                                                         const double* v, size_t n, double* x,
                                                         double* y, double* z) {
  constexpr int kVectors = kBlock / kLanes;
  const bool cbrt = shape.e == 1.0 / 3;
  size_t i = 0;
  for (; i + kBlock <= n; i += kBlock) {
    // Outside [0, 1] (or NaN) the scalar reference takes over.
    Ints outside{};
    for (int j = 0; j < kVectors; ++j) {
      const Doubles a = Load(u + i + j * kLanes), b = Load(v + i + j * kLanes);
      outside |= ~((a >= 0) & (a <= 1) & (b >= 0) & (b <= 1));
    }
    if (Any(outside)) break;
    // trig[0..3][j]: cos a, sin a, cos b, sin b of vector j; then their signed powers.
    Doubles trig[4][kVectors], power[4][kVectors];
    for (int j = 0; j < kVectors; ++j) {
      const Doubles a = Load(u + i + j * kLanes), b = Load(v + i + j * kLanes);
      CosSin(AngleOf(a, -1, 2, shape.reparam), &trig[0][j], &trig[1][j]);
      CosSin(AngleOf(b, -2, 4, shape.reparam), &trig[2][j], &trig[3][j]);
    }
    for (int k = 0; k < 4; ++k) {
      for (int j = 0; j < kVectors; ++j) power[k][j] = Power(Abs(trig[k][j]), shape.e, cbrt);
    }
    for (int j = 0; j < kVectors; ++j) {
      const Doubles ca = CopySign(power[0][j], trig[0][j]), sa = CopySign(power[1][j], trig[1][j]);
      const Doubles cb = CopySign(power[2][j], trig[2][j]), sb = CopySign(power[3][j], trig[3][j]);
      Store(ca * cb, x + i + j * kLanes), Store(ca * sb, y + i + j * kLanes);
      Store(sa, z + i + j * kLanes);
    }
  }
  return i;
}

}  // namespace
}  // namespace sfc::superellipsoid_internal

#endif  // SFCSAMPLER_CORE_SUPERELLIPSOID_LANES_H_
