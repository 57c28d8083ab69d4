// Built with -mavx (core/CMakeLists.txt): only loads, stores and SLEEF's
// cinz call, so no arithmetic of ours can be contracted differently.
#include <immintrin.h>
#include <sleef.h>

#include "core/vector_math.h"

namespace sfc::math::vector_math_internal {

void SinCosPiAvx(const double* x, size_t n, double* s, double* c) {
  for (size_t i = 0; i < n; i += 4) {
    const Sleef___m256d_2 r = Sleef_cinz_sincospid4_u35avx(_mm256_loadu_pd(x + i));
    _mm256_storeu_pd(s + i, r.x);
    _mm256_storeu_pd(c + i, r.y);
  }
}

void SinCosOfAvx(const double* x, size_t n, double* s, double* c) {
  for (size_t i = 0; i < n; i += 4) {
    const Sleef___m256d_2 r = Sleef_cinz_sincosd4_u10avx(_mm256_loadu_pd(x + i));
    _mm256_storeu_pd(s + i, r.x);
    _mm256_storeu_pd(c + i, r.y);
  }
}

void PowAvx(const double* x, double y, size_t n, double* out) {
  const __m256d e = _mm256_set1_pd(y);
  for (size_t i = 0; i < n; i += 4)
    _mm256_storeu_pd(out + i, Sleef_cinz_powd4_u10avx(_mm256_loadu_pd(x + i), e));
}

void CbrtAvx(const double* x, size_t n, double* out) {
  for (size_t i = 0; i < n; i += 4)
    _mm256_storeu_pd(out + i, Sleef_cinz_cbrtd4_u35avx(_mm256_loadu_pd(x + i)));
}

}  // namespace sfc::math::vector_math_internal
