// Built with -mavx2 -ffp-contract=off (core/CMakeLists.txt): the AVX2 paths
// of TreeWarp (core/tree_warp_internal.h), four lanes to a vector, each lane
// the scalar code's IEEE operations and integer look-ups in
// core/tree_warp.cc, so their bits are the scalar path's. Run only on the
// kAvx2 vector path.
#include <immintrin.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>

#include "core/tree_warp_internal.h"

namespace sfc::tree_warp_internal {
namespace {

// std::clamp(v, 0, kBelowOne), lane by lane.
inline __m256d ClampBelowOne(__m256d v) {
  const __m256d zero = _mm256_setzero_pd(), below_one = _mm256_set1_pd(kBelowOne);
  const __m256d r = _mm256_blendv_pd(v, below_one, _mm256_cmp_pd(below_one, v, _CMP_LT_OQ));
  return _mm256_blendv_pd(r, zero, _mm256_cmp_pd(v, zero, _CMP_LT_OQ));
}

// All-ones lanes as a double mask and back.
inline __m256d AsMask(__m256i m) { return _mm256_castsi256_pd(m); }
inline __m256i AsLanes(__m256d m) { return _mm256_castpd_si256(m); }

}  // namespace

// Descend<2> (TreeWarp::Descend) for the points i < m in vectors of four
// lanes on AVX2, each lane the scalar code's steps (Pick's compare, select,
// subtract, multiply and clamp; the nodes' entries gathered); lanes at their
// leaves are masked. Returns how many points it took (a multiple of four, at
// most 64); the caller descends the rest.
size_t DescendGrid2Avx2(size_t m, double* a, double* b, int32_t* ref, uint8_t* state,
                        const double* splits, const int32_t* children, const int32_t* state_at) {
  const __m256d zero = _mm256_setzero_pd();
  const __m256i minus_one = _mm256_set1_epi64x(-1), one = _mm256_set1_epi64x(1);
  const __m256i two = _mm256_set1_epi64x(2), four = _mm256_set1_epi64x(4);
  // Up to 16 vectors side by side, a level each per round, so that their
  // gathers overlap.
  constexpr size_t kVectors = 16;
  const size_t vectors = std::min(m / 4, kVectors);
  __m256d va[kVectors], vb[kVectors];
  __m256i vref[kVectors], vstate[kVectors];
  for (size_t v = 0; v < vectors; ++v) {
    va[v] = _mm256_loadu_pd(a + 4 * v), vb[v] = _mm256_loadu_pd(b + 4 * v);
    vref[v] = _mm256_cvtepi32_epi64(_mm_loadu_si128(reinterpret_cast<__m128i*>(ref + 4 * v)));
    int32_t s4;
    __builtin_memcpy(&s4, state + 4 * v, 4);
    vstate[v] = _mm256_cvtepu8_epi64(_mm_cvtsi32_si128(s4));
  }
  for (bool descending = vectors > 0; descending;) {
    descending = false;
    for (size_t v = 0; v < vectors; ++v) {
      const __m256i active = _mm256_cmpgt_epi64(vref[v], minus_one);
      if (_mm256_testz_si256(active, active)) continue;
      descending = true;
      const __m256d active_d = AsMask(active);
      // Node entries at ref * 12: the columns' bounds and inverse widths, then
      // each column's rows' (TreeWarp::splits_, grid 2).
      const __m256i node =
          _mm256_add_epi64(_mm256_slli_epi64(vref[v], 3), _mm256_slli_epi64(vref[v], 2));
      // One split, the column's (x at `at`) or the row's: the side x falls
      // on (d, 0 or 1) and x rescaled to it.
      auto pick = [&](__m256d x, __m256i at, __m256i* d) {
        const __m256d bound = _mm256_mask_i64gather_pd(zero, splits, at, active_d, 8);
        const __m256d beyond = _mm256_cmp_pd(x, bound, _CMP_GE_OQ);
        *d = _mm256_and_si256(AsLanes(beyond), one);
        const __m256d inverse = _mm256_mask_i64gather_pd(
            zero, splits, _mm256_add_epi64(at, _mm256_add_epi64(*d, two)), active_d, 8);
        return ClampBelowOne(
            _mm256_mul_pd(_mm256_sub_pd(x, _mm256_and_pd(beyond, bound)), inverse));
      };
      __m256i dx, dy;
      const __m256d na = pick(va[v], node, &dx);
      const __m256i rows = _mm256_add_epi64(node, _mm256_add_epi64(_mm256_slli_epi64(dx, 2), four));
      const __m256d nb = pick(vb[v], rows, &dy);
      const __m256i at = _mm256_add_epi64(_mm256_slli_epi64(dy, 1), dx);
      // The 32-bit look-ups' mask: each 64-bit lane's low half.
      const __m128i active32 = _mm256_castsi256_si128(
          _mm256_permutevar8x32_epi32(active, _mm256_setr_epi32(0, 2, 4, 6, 0, 2, 4, 6)));
      const __m256i child = _mm256_cvtepi32_epi64(_mm256_mask_i64gather_epi32(
          _mm_setzero_si128(), children, _mm256_add_epi64(_mm256_slli_epi64(vref[v], 2), at),
          active32, 4));
      const __m256i next_state = _mm256_cvtepi32_epi64(_mm256_mask_i64gather_epi32(
          _mm_setzero_si128(), state_at, _mm256_add_epi64(_mm256_slli_epi64(vstate[v], 2), at),
          active32, 4));
      va[v] = _mm256_blendv_pd(va[v], na, active_d);
      vb[v] = _mm256_blendv_pd(vb[v], nb, active_d);
      vref[v] = _mm256_blendv_epi8(vref[v], child, active);
      vstate[v] = _mm256_blendv_epi8(vstate[v], next_state, active);
    }
  }
  for (size_t v = 0; v < vectors; ++v) {
    _mm256_storeu_pd(a + 4 * v, va[v]);
    _mm256_storeu_pd(b + 4 * v, vb[v]);
    alignas(32) int64_t r[4], s[4];
    _mm256_store_si256(reinterpret_cast<__m256i*>(r), vref[v]);
    _mm256_store_si256(reinterpret_cast<__m256i*>(s), vstate[v]);
    for (int j = 0; j < 4; ++j) {
      ref[4 * v + j] = static_cast<int32_t>(r[j]);
      state[4 * v + j] = static_cast<uint8_t>(s[j]);
    }
  }
  return 4 * vectors;
}

namespace {

// min(uint64(std::max(0.0, v) * cells), top) lane by lane, for v * cells <
// 2^31 (std::max keeps 0 unless 0 < v; the truncation is then the scalar
// conversion's).
inline __m256i CellsOf(__m256d v, __m256d cells, __m128i top) {
  const __m256d zero = _mm256_setzero_pd();
  const __m256d kept = _mm256_and_pd(_mm256_cmp_pd(zero, v, _CMP_LT_OQ), v);
  const __m128i c = _mm256_cvttpd_epi32(_mm256_mul_pd(kept, cells));
  return _mm256_cvtepu32_epi64(_mm_min_epu32(c, top));
}

}  // namespace

// TreeWarp::DigitsInLeaf for a Hilbert tree (grid 2, chunks of 4 levels:
// encode's 16 x 16 cells) on AVX2, four points to a vector: the same integer
// steps (the column and row by the same double product and truncation, each
// level's and chunk's look-ups gathered). Returns how many points it took (a
// multiple of four; none unless cells <= 2^30); the caller encodes the rest.
size_t DigitsGrid2Avx2(size_t m, const double* x, const double* y, const uint8_t* state,
                       double cells, uint64_t top, int chunks, int head, const int32_t* child_at,
                       const int32_t* state_at, const uint64_t* encode, uint64_t* digits) {
  if (!(cells <= 0x1.0p30)) return 0;
  const __m256d scale = _mm256_set1_pd(cells);
  const __m128i top_v = _mm_set1_epi32(static_cast<int32_t>(top));
  const __m256i low4 = _mm256_set1_epi64x(15), low1 = _mm256_set1_epi64x(1);
  const __m256i digit_mask = _mm256_set1_epi64x(static_cast<int64_t>((uint64_t{1} << 56) - 1));
  const long long* encode_ll = reinterpret_cast<const long long*>(encode);
  size_t i0 = 0;
  for (; i0 + 4 <= m; i0 += 4) {
    const __m256i cx = CellsOf(_mm256_loadu_pd(x + i0), scale, top_v);
    const __m256i cy = CellsOf(_mm256_loadu_pd(y + i0), scale, top_v);
    int32_t s4;
    __builtin_memcpy(&s4, state + i0, 4);
    __m256i s = _mm256_cvtepu8_epi64(_mm_cvtsi32_si128(s4));
    __m256i d = _mm256_setzero_si256();
    // The leading levels, above the chunks, one at a time.
    for (int level = head - 1; level >= 0; --level) {
      const int shift = 4 * chunks + level;
      const __m256i dx = _mm256_and_si256(_mm256_srli_epi64(cx, shift), low1);
      const __m256i dy = _mm256_and_si256(_mm256_srli_epi64(cy, shift), low1);
      const __m256i at =
          _mm256_add_epi64(_mm256_add_epi64(_mm256_slli_epi64(s, 2), _mm256_slli_epi64(dy, 1)), dx);
      const __m256i child = _mm256_cvtepi32_epi64(_mm256_i64gather_epi32(child_at, at, 4));
      d = _mm256_add_epi64(_mm256_slli_epi64(d, 2), child);
      s = _mm256_cvtepi32_epi64(_mm256_i64gather_epi32(state_at, at, 4));
    }
    for (int c = chunks - 1; c >= 0; --c) {
      const __m256i xs = _mm256_and_si256(_mm256_srli_epi64(cx, 4 * c), low4);
      const __m256i ys = _mm256_and_si256(_mm256_srli_epi64(cy, 4 * c), low4);
      const __m256i cell =
          _mm256_add_epi64(_mm256_slli_epi64(s, 8), _mm256_add_epi64(_mm256_slli_epi64(ys, 4), xs));
      const __m256i e = _mm256_i64gather_epi64(encode_ll, cell, 8);
      d = _mm256_add_epi64(_mm256_slli_epi64(d, 8), _mm256_and_si256(e, digit_mask));
      s = _mm256_srli_epi64(e, 56);
    }
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(digits + i0), d);
  }
  return i0;
}

namespace {

// CdfInversion's F(x) = x (p0 + x (p1 / 2 + x (p2 / 3))), lane by lane.
inline __m256d CdfLanes(__m256d x, __m256d p0, __m256d half_p1, __m256d third_p2) {
  return _mm256_mul_pd(
      x, _mm256_add_pd(p0, _mm256_mul_pd(x, _mm256_add_pd(half_p1, _mm256_mul_pd(x, third_p2)))));
}

}  // namespace

// InvertCdfs on AVX2: the problems four lanes to a vector, each lane
// CdfInversion::Step's operations (both of its branches computed, one
// selected; a lane that is done keeps its value), up to 16 vectors a step
// each per round.
void InvertCdfsAvx2(size_t n, const uint8_t* lanes, const double (*p)[3], const double* share,
                    double* out) {
  constexpr size_t kMax = 64, kVectors = kMax / 4;
  alignas(32) double p0[kMax], p1[kMax], p2[kMax], sh[kMax], result[kMax];
  for (size_t j = 0; j < kMax; ++j) {  // the padding: a problem of its own, never read
    p0[j] = j < n ? p[lanes[j]][0] : 1.0;
    p1[j] = j < n ? p[lanes[j]][1] : 0.0;
    p2[j] = j < n ? p[lanes[j]][2] : 0.0;
    sh[j] = j < n ? share[lanes[j]] : 0.5;
  }
  const size_t vectors = (n + 3) / 4;
  const __m256d zero = _mm256_setzero_pd(), one = _mm256_set1_pd(1.0);
  const __m256d two = _mm256_set1_pd(2.0), three = _mm256_set1_pd(3.0);
  const __m256d tiny_step = _mm256_set1_pd(0x1.0p-44), tiny_bracket = _mm256_set1_pd(0x1.0p-52);
  const __m256d sign = _mm256_set1_pd(-0.0);
  __m256d c0[kVectors], c1[kVectors], c2[kVectors], half_c1[kVectors], third_c2[kVectors];
  __m256d target[kVectors], lo[kVectors], hi[kVectors], s[kVectors], active[kVectors];
  for (size_t v = 0; v < vectors; ++v) {
    c0[v] = _mm256_load_pd(p0 + 4 * v), c1[v] = _mm256_load_pd(p1 + 4 * v);
    c2[v] = _mm256_load_pd(p2 + 4 * v);
    half_c1[v] = _mm256_div_pd(c1[v], two), third_c2[v] = _mm256_div_pd(c2[v], three);
    const __m256d share_v = _mm256_load_pd(sh + 4 * v);
    target[v] = _mm256_mul_pd(share_v, CdfLanes(one, c0[v], half_c1[v], third_c2[v]));
    lo[v] = zero, hi[v] = one, s[v] = share_v;
    active[v] = _mm256_cmp_pd(zero, zero, _CMP_EQ_OQ);
  }
  for (int step = 0; step < kCdfMaxSteps; ++step) {
    bool any = false;
    for (size_t v = 0; v < vectors; ++v) {
      if (_mm256_testz_pd(active[v], active[v])) continue;
      any = true;
      const __m256d f = _mm256_sub_pd(CdfLanes(s[v], c0[v], half_c1[v], third_c2[v]), target[v]);
      const __m256d moving = _mm256_andnot_pd(_mm256_cmp_pd(f, zero, _CMP_EQ_OQ), active[v]);
      const __m256d above = _mm256_cmp_pd(f, zero, _CMP_GT_OQ);
      const __m256d new_hi = _mm256_blendv_pd(hi[v], s[v], _mm256_and_pd(moving, above));
      const __m256d new_lo = _mm256_blendv_pd(lo[v], s[v], _mm256_andnot_pd(above, moving));
      const __m256d d = _mm256_add_pd(
          c0[v], _mm256_mul_pd(s[v], _mm256_add_pd(c1[v], _mm256_mul_pd(s[v], c2[v]))));
      const __m256d middle = _mm256_div_pd(_mm256_add_pd(new_lo, new_hi), two);
      __m256d next = _mm256_blendv_pd(middle, _mm256_sub_pd(s[v], _mm256_div_pd(f, d)),
                                      _mm256_cmp_pd(d, zero, _CMP_GT_OQ));
      const __m256d inside = _mm256_and_pd(_mm256_cmp_pd(next, new_lo, _CMP_GT_OQ),
                                           _mm256_cmp_pd(next, new_hi, _CMP_LT_OQ));
      next = _mm256_blendv_pd(middle, next, inside);
      const __m256d converged = _mm256_or_pd(
          _mm256_cmp_pd(_mm256_andnot_pd(sign, _mm256_sub_pd(next, s[v])), tiny_step, _CMP_LE_OQ),
          _mm256_cmp_pd(_mm256_sub_pd(new_hi, new_lo), tiny_bracket, _CMP_LE_OQ));
      lo[v] = _mm256_blendv_pd(lo[v], new_lo, moving);
      hi[v] = _mm256_blendv_pd(hi[v], new_hi, moving);
      s[v] = _mm256_blendv_pd(s[v], next, moving);
      active[v] = _mm256_andnot_pd(converged, moving);
    }
    if (!any) break;
  }
  for (size_t v = 0; v < vectors; ++v) _mm256_store_pd(result + 4 * v, s[v]);
  for (size_t j = 0; j < n; ++j) out[lanes[j]] = result[j];
}

}  // namespace sfc::tree_warp_internal
