// Built with -mavx512f (core/CMakeLists.txt): only loads, stores and SLEEF's
// cinz call, so no arithmetic of ours can be contracted differently.
#include <immintrin.h>
#include <sleef.h>

#include "core/vector_math.h"

namespace sfc::math::vector_math_internal {

void SinCosPiAvx512(const double* x, size_t n, double* s, double* c) {
  for (size_t i = 0; i < n; i += 8) {
    const Sleef___m512d_2 r = Sleef_cinz_sincospid8_u35avx512fnofma(_mm512_loadu_pd(x + i));
    _mm512_storeu_pd(s + i, r.x);
    _mm512_storeu_pd(c + i, r.y);
  }
}

void SinCosOfAvx512(const double* x, size_t n, double* s, double* c) {
  for (size_t i = 0; i < n; i += 8) {
    const Sleef___m512d_2 r = Sleef_cinz_sincosd8_u10avx512fnofma(_mm512_loadu_pd(x + i));
    _mm512_storeu_pd(s + i, r.x);
    _mm512_storeu_pd(c + i, r.y);
  }
}

void PowAvx512(const double* x, double y, size_t n, double* out) {
  const __m512d e = _mm512_set1_pd(y);
  for (size_t i = 0; i < n; i += 8)
    _mm512_storeu_pd(out + i, Sleef_cinz_powd8_u10avx512fnofma(_mm512_loadu_pd(x + i), e));
}

void CbrtAvx512(const double* x, size_t n, double* out) {
  for (size_t i = 0; i < n; i += 8)
    _mm512_storeu_pd(out + i, Sleef_cinz_cbrtd8_u35avx512fnofma(_mm512_loadu_pd(x + i)));
}

}  // namespace sfc::math::vector_math_internal
