#include "core/vector_math.h"

#include <algorithm>
#include <emmintrin.h>
#include <cstdlib>
#include <sleef.h>

namespace sfc::math {
namespace {

VectorPath Widest() {
  VectorPath widest = VectorPath::kScalar;
  for (VectorPath path : kVectorPaths) {
    if (Runs(path)) widest = path;
  }
  return widest;
}

// The widest path, or another one this CPU runs named by
// SFCSAMPLER_VECTOR_PATH (for checking that every path gives the same bytes
// end to end).
VectorPath Detect() {
  const char* name = std::getenv("SFCSAMPLER_VECTOR_PATH");
  if (name != nullptr) {
    for (VectorPath path : kVectorPaths) {
      if (VectorPathName(path) == name && Runs(path)) return path;
    }
  }
  return Widest();
}

// Whole vectors of `width` by `body`(x, n, s, c); a tail of two or more
// values as one more vector, padded with zeros (each lane's value is its own,
// so the same bits), a single value by `one`(x, &s, &c), the scalar
// reference. A function of one result passes c = nullptr.
template <typename Body, typename One>
void Batched(const double* x, size_t n, double* s, double* c, size_t width, Body body, One one) {
  const size_t whole = n / width * width, tail = n - whole;
  body(x, whole, s, c);
  if (tail >= 2) {
    double xp[8] = {}, sp[8], cp[8];
    std::copy(x + whole, x + n, xp);
    body(xp, width, sp, c == nullptr ? nullptr : cp);
    std::copy(sp, sp + tail, s + whole);
    if (c != nullptr) std::copy(cp, cp + tail, c + whole);
  } else if (tail == 1) {
    one(x[whole], s + whole, c == nullptr ? nullptr : c + whole);
  }
}

void SinCosPiSse2(const double* x, size_t n, double* s, double* c) {
  for (size_t i = 0; i < n; i += 2) {
    const Sleef___m128d_2 r = Sleef_cinz_sincospid2_u35sse2(_mm_loadu_pd(x + i));
    _mm_storeu_pd(s + i, r.x);
    _mm_storeu_pd(c + i, r.y);
  }
}

void SinCosOfSse2(const double* x, size_t n, double* s, double* c) {
  for (size_t i = 0; i < n; i += 2) {
    const Sleef___m128d_2 r = Sleef_cinz_sincosd2_u10sse2(_mm_loadu_pd(x + i));
    _mm_storeu_pd(s + i, r.x);
    _mm_storeu_pd(c + i, r.y);
  }
}

void PowSse2(const double* x, double y, size_t n, double* out) {
  const __m128d e = _mm_set1_pd(y);
  for (size_t i = 0; i < n; i += 2)
    _mm_storeu_pd(out + i, Sleef_cinz_powd2_u10sse2(_mm_loadu_pd(x + i), e));
}

void CbrtSse2(const double* x, size_t n, double* out) {
  for (size_t i = 0; i < n; i += 2)
    _mm_storeu_pd(out + i, Sleef_cinz_cbrtd2_u35sse2(_mm_loadu_pd(x + i)));
}

// A batch function on `path`: its scalar reference `scalar`(), or its SSE2,
// AVX or AVX-512F loop by Batched; kAvx2 runs the AVX loop (WithoutAvx2).
template <typename Scalar, typename Body, typename One>
void OnPath(VectorPath path, const double* x, size_t n, double* s, double* c, Scalar scalar,
            Body sse2, Body avx, Body avx512, One one) {
  const VectorPath built = WithoutAvx2(path);
  if (built == VectorPath::kScalar) return scalar();
  if (built == VectorPath::kSse2) return Batched(x, n, s, c, 2, sse2, one);
  if (built == VectorPath::kAvx) return Batched(x, n, s, c, 4, avx, one);
  Batched(x, n, s, c, 8, avx512, one);
}

}  // namespace

// One value through lane 0 of the SSE2 functions: ~20% faster than SLEEF's
// portable scalar code (purec), with its bits (tests/vector_math_test.cc).
SinCos SinCosPi(double x) {
  const Sleef___m128d_2 r = Sleef_cinz_sincospid2_u35sse2(_mm_set_sd(x));
  return {_mm_cvtsd_f64(r.x), _mm_cvtsd_f64(r.y)};
}

SinCos SinCosOf(double x) {
  const Sleef___m128d_2 r = Sleef_cinz_sincosd2_u10sse2(_mm_set_sd(x));
  return {_mm_cvtsd_f64(r.x), _mm_cvtsd_f64(r.y)};
}

double Pow(double x, double y) {
  return _mm_cvtsd_f64(Sleef_cinz_powd2_u10sse2(_mm_set_sd(x), _mm_set_sd(y)));
}
double Cbrt(double x) { return _mm_cvtsd_f64(Sleef_cinz_cbrtd2_u35sse2(_mm_set_sd(x))); }
double Exp(double x) { return Sleef_cinz_expd1_u10purec(x); }
double Log(double x) { return Sleef_cinz_logd1_u10purec(x); }
double Log2(double x) { return Sleef_cinz_log2d1_u10purec(x); }
double Log10(double x) { return Sleef_cinz_log10d1_u10purec(x); }
double Tan(double x) { return Sleef_cinz_tand1_u10purec(x); }
double Asin(double x) { return Sleef_cinz_asind1_u10purec(x); }
double Acos(double x) { return Sleef_cinz_acosd1_u10purec(x); }
double Atan(double x) { return Sleef_cinz_atand1_u10purec(x); }
double Atan2(double y, double x) { return Sleef_cinz_atan2d1_u10purec(y, x); }
double Sinh(double x) { return Sleef_cinz_sinhd1_u10purec(x); }
double Cosh(double x) { return Sleef_cinz_coshd1_u10purec(x); }
double Tanh(double x) { return Sleef_cinz_tanhd1_u10purec(x); }
double Asinh(double x) { return Sleef_cinz_asinhd1_u10purec(x); }
double Acosh(double x) { return Sleef_cinz_acoshd1_u10purec(x); }
double Atanh(double x) { return Sleef_cinz_atanhd1_u10purec(x); }

VectorPath BestVectorPath() {
  static const VectorPath best = Detect();
  return best;
}

std::string_view VectorPathName(VectorPath path) {
  switch (path) {
    case VectorPath::kScalar: return "scalar";
    case VectorPath::kSse2: return "sse2";
    case VectorPath::kAvx: return "avx";
    case VectorPath::kAvx2: return "avx2";
    case VectorPath::kAvx512: return "avx512f";
  }
  return "?";
}

bool Runs(VectorPath path) {
  __builtin_cpu_init();
  switch (path) {
    case VectorPath::kScalar:
    case VectorPath::kSse2: return true;  // every x86-64 CPU
    case VectorPath::kAvx: return __builtin_cpu_supports("avx");
    case VectorPath::kAvx2: return __builtin_cpu_supports("avx2");
    case VectorPath::kAvx512: return __builtin_cpu_supports("avx512f");
  }
  return false;
}

void SinCosPiOn(VectorPath path, const double* x, size_t n, double* s, double* c) {
  auto scalar = [&] {  // SLEEF's portable C: the reference
    for (size_t i = 0; i < n; ++i) {
      const Sleef_double_2 r = Sleef_cinz_sincospid1_u35purec(x[i]);
      s[i] = r.x, c[i] = r.y;
    }
  };
  auto one = [](double x, double* s, double* c) {
    const SinCos r = SinCosPi(x);
    *s = r.sin, *c = r.cos;
  };
  OnPath(path, x, n, s, c, scalar, SinCosPiSse2, vector_math_internal::SinCosPiAvx,
         vector_math_internal::SinCosPiAvx512, one);
}

void SinCosPi(const double* x, size_t n, double* s, double* c) {
  SinCosPiOn(BestVectorPath(), x, n, s, c);
}

void SinCosOfOn(VectorPath path, const double* x, size_t n, double* s, double* c) {
  auto scalar = [&] {
    for (size_t i = 0; i < n; ++i) {
      const Sleef_double_2 r = Sleef_cinz_sincosd1_u10purec(x[i]);
      s[i] = r.x, c[i] = r.y;
    }
  };
  auto one = [](double x, double* s, double* c) {
    const SinCos r = SinCosOf(x);
    *s = r.sin, *c = r.cos;
  };
  OnPath(path, x, n, s, c, scalar, SinCosOfSse2, vector_math_internal::SinCosOfAvx,
         vector_math_internal::SinCosOfAvx512, one);
}

void SinCosOf(const double* x, size_t n, double* s, double* c) {
  SinCosOfOn(BestVectorPath(), x, n, s, c);
}

void PowOn(VectorPath path, const double* x, double y, size_t n, double* out) {
  auto scalar = [&] {
    for (size_t i = 0; i < n; ++i) out[i] = Sleef_cinz_powd1_u10purec(x[i], y);
  };
  auto one = [y](double x, double* r, double*) { *r = Pow(x, y); };
  auto with = [y](void (*body)(const double*, double, size_t, double*)) {
    return [y, body](const double* x, size_t n, double* r, double*) { body(x, y, n, r); };
  };
  OnPath(path, x, n, out, nullptr, scalar, with(PowSse2), with(vector_math_internal::PowAvx),
         with(vector_math_internal::PowAvx512), one);
}

void Pow(const double* x, double y, size_t n, double* out) {
  PowOn(BestVectorPath(), x, y, n, out);
}

void CbrtOn(VectorPath path, const double* x, size_t n, double* out) {
  auto scalar = [&] {
    for (size_t i = 0; i < n; ++i) out[i] = Sleef_cinz_cbrtd1_u35purec(x[i]);
  };
  auto one = [](double x, double* r, double*) { *r = Cbrt(x); };
  auto with = [](void (*body)(const double*, size_t, double*)) {
    return [body](const double* x, size_t n, double* r, double*) { body(x, n, r); };
  };
  OnPath(path, x, n, out, nullptr, scalar, with(CbrtSse2), with(vector_math_internal::CbrtAvx),
         with(vector_math_internal::CbrtAvx512), one);
}

void Cbrt(const double* x, size_t n, double* out) { CbrtOn(BestVectorPath(), x, n, out); }

}  // namespace sfc::math
