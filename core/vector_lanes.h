// Generic vectors for batch loops written once and compiled once per
// instruction set (GCC's vector extensions): kLanes doubles or 64-bit
// integers to a vector, as many as the build's registers hold, and what the
// extensions lack or split into many instructions (a test of any lane,
// gathers, widening loads and narrowing stores), each one instruction where
// the build has it. The loops of mesh/mesh_warp_lanes.h and
// core/tree_warp_lanes.h are written in these.
//
// Internal linkage on purpose (an anonymous namespace): each file that
// includes this keeps its own copy, compiled for its instruction set, which
// the linker never merges with another file's.
//
// Thread-safety: pure functions.
#ifndef SFCSAMPLER_CORE_VECTOR_LANES_H_
#define SFCSAMPLER_CORE_VECTOR_LANES_H_

#include <cstdint>
#include <cstring>
#include <type_traits>

#if defined(__AVX512F__) || defined(__AVX2__)
#include <immintrin.h>
#endif

namespace sfc::vector_lanes {
namespace {

// As many lanes as the build's registers hold: 8 with AVX-512F, 4 with AVX,
// 2 in the baseline's SSE2 (wider generic vectors there would be split into
// many registers, spilled and partly done a lane at a time: three times
// slower).
#if defined(__AVX512F__)
constexpr int kLanes = 8;
#elif defined(__AVX__)
constexpr int kLanes = 4;
#else
constexpr int kLanes = 2;
#endif
typedef double Doubles __attribute__((vector_size(8 * kLanes)));
typedef int64_t Ints __attribute__((vector_size(8 * kLanes)));
typedef uint64_t Words __attribute__((vector_size(8 * kLanes)));
// kLanes 32-bit values (what a conversion or a gather of them gives).
typedef int32_t Int32s __attribute__((vector_size(4 * kLanes)));
typedef uint32_t Uint32s __attribute__((vector_size(4 * kLanes)));

// 32-bit lanes widened to 64 bits, sign-extended (Int32s) or zero-extended
// (Uint32s): one instruction where the build has AVX-512F or AVX2 (GCC's
// own conversion splits the AVX-512F one in two).
template <typename Narrow>
__attribute__((always_inline)) inline Ints Widen(Narrow x) {
  constexpr bool kSigned = std::is_same_v<Narrow, Int32s>;
  static_assert(kSigned || std::is_same_v<Narrow, Uint32s>);
#ifdef __AVX512F__
  return (Ints)(kSigned ? _mm512_maskz_cvtepi32_epi64(0xff, (__m256i)x)
                        : _mm512_maskz_cvtepu32_epi64(0xff, (__m256i)x));
#elif defined(__AVX2__)
  return (Ints)(kSigned ? _mm256_cvtepi32_epi64((__m128i)x) : _mm256_cvtepu32_epi64((__m128i)x));
#else
  return __builtin_convertvector(x, Ints);
#endif
}

// kLanes bytes at p, each zero-extended to a lane.
__attribute__((always_inline)) inline Ints LoadBytes(const uint8_t* p) {
#ifdef __AVX512F__
  return (Ints)_mm512_maskz_cvtepu8_epi64(0xff,
                                          _mm_loadl_epi64(reinterpret_cast<const __m128i*>(p)));
#elif defined(__AVX2__)
  int32_t four;
  std::memcpy(&four, p, 4);
  return (Ints)_mm256_cvtepu8_epi64(_mm_cvtsi32_si128(four));
#else
  Ints r;
  for (int k = 0; k < kLanes; ++k) r[k] = p[k];
  return r;
#endif
}
// kLanes 32-bit values at p, each sign-extended to a lane.
__attribute__((always_inline)) inline Ints LoadInt32s(const int32_t* p) {
  Int32s v;
  std::memcpy(&v, p, sizeof v);
  return Widen(v);
}
// Each lane's low bits to p[k] (T int32_t or uint8_t).
template <typename T>
__attribute__((always_inline)) inline void StoreNarrowed(Ints v, T* p) {
  static_assert(std::is_same_v<T, int32_t> || std::is_same_v<T, uint8_t>);
#ifdef __AVX512F__
  if constexpr (sizeof(T) == 4) {
    _mm512_mask_cvtepi64_storeu_epi32(p, 0xff, (__m512i)v);
  } else {
    _mm512_mask_cvtepi64_storeu_epi8(p, 0xff, (__m512i)v);
  }
#else
  for (int k = 0; k < kLanes; ++k) p[k] = static_cast<T>(v[k]);
#endif
}

// Whether any lane of a mask (all ones or zero in each lane) is set.
__attribute__((always_inline)) inline bool Any(Ints mask) {
#ifdef __AVX512F__
  return _mm512_test_epi64_mask((__m512i)mask, (__m512i)mask) != 0;
#elif defined(__AVX2__)
  return !_mm256_testz_si256((__m256i)mask, (__m256i)mask);
#else
  int64_t any = 0;
  for (int k = 0; k < kLanes; ++k) any |= mask[k];
  return any != 0;
#endif
}

// p[index[k]] in each lane: one gather instruction where the build has
// AVX-512F or AVX2.
__attribute__((always_inline)) inline Doubles Gather(const double* p, Ints index) {
#ifdef __AVX512F__
  return (Doubles)_mm512_mask_i64gather_pd(_mm512_setzero_pd(), 0xff, (__m512i)index, p, 8);
#elif defined(__AVX2__)
  return (Doubles)_mm256_i64gather_pd(p, (__m256i)index, 8);
#else
  Doubles r;
  for (int k = 0; k < kLanes; ++k) r[k] = p[index[k]];
  return r;
#endif
}
// The same for 32-bit values (T int32_t or uint32_t), widened to 64 bits as
// their type says (sign- or zero-extended).
template <typename T>
__attribute__((always_inline)) inline Ints Gather(const T* p, Ints index) {
  static_assert(sizeof(T) == 4);
  using Narrow [[maybe_unused]] = std::conditional_t<std::is_signed_v<T>, Int32s, Uint32s>;
#ifdef __AVX512F__
  return Widen(
      (Narrow)_mm512_mask_i64gather_epi32(_mm256_setzero_si256(), 0xff, (__m512i)index, p, 4));
#elif defined(__AVX2__)
  return Widen((Narrow)_mm256_i64gather_epi32(reinterpret_cast<const int*>(p), (__m256i)index, 4));
#else
  Ints r;
  for (int k = 0; k < kLanes; ++k) r[k] = p[index[k]];
  return r;
#endif
}
__attribute__((always_inline)) inline Words Gather(const uint64_t* p, Ints index) {
#ifdef __AVX512F__
  return (Words)_mm512_mask_i64gather_epi64(_mm512_setzero_si512(), 0xff, (__m512i)index, p, 8);
#elif defined(__AVX2__)
  return (Words)_mm256_i64gather_epi64(reinterpret_cast<const long long*>(p), (__m256i)index, 8);
#else
  Words r;
  for (int k = 0; k < kLanes; ++k) r[k] = p[index[k]];
  return r;
#endif
}

// p[index[k]] in the lanes where `mask` is set, 0 in the others, whose
// indices are never read (they may lie outside p).
__attribute__((always_inline)) inline Doubles GatherWhere(const double* p, Ints index, Ints mask) {
#ifdef __AVX512F__
  const __mmask8 m = _mm512_test_epi64_mask((__m512i)mask, (__m512i)mask);
  return (Doubles)_mm512_mask_i64gather_pd(_mm512_setzero_pd(), m, (__m512i)index, p, 8);
#elif defined(__AVX2__)
  return (Doubles)_mm256_mask_i64gather_pd(_mm256_setzero_pd(), p, (__m256i)index, (__m256d)mask,
                                           8);
#else
  Doubles r{};
  for (int k = 0; k < kLanes; ++k) r[k] = mask[k] ? p[index[k]] : 0.0;
  return r;
#endif
}
// The same, sign-extended to 64 bits.
__attribute__((always_inline)) inline Ints GatherWhere(const int32_t* p, Ints index, Ints mask) {
#ifdef __AVX512F__
  const __mmask8 m = _mm512_test_epi64_mask((__m512i)mask, (__m512i)mask);
  return Widen(
      (Int32s)_mm512_mask_i64gather_epi32(_mm256_setzero_si256(), m, (__m512i)index, p, 4));
#elif defined(__AVX2__)
  // The 32-bit lanes' mask: each 64-bit lane's low half.
  const __m128i m = _mm256_castsi256_si128(
      _mm256_permutevar8x32_epi32((__m256i)mask, _mm256_setr_epi32(0, 2, 4, 6, 0, 2, 4, 6)));
  return Widen((Int32s)_mm256_mask_i64gather_epi32(_mm_setzero_si128(), p, (__m256i)index, m, 4));
#else
  Ints r{};
  for (int k = 0; k < kLanes; ++k) r[k] = mask[k] ? p[index[k]] : 0;
  return r;
#endif
}

}  // namespace
}  // namespace sfc::vector_lanes

#endif  // SFCSAMPLER_CORE_VECTOR_LANES_H_
