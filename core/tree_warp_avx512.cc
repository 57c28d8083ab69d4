// Built with -mavx512f -ffp-contract=off (core/CMakeLists.txt): the AVX-512F
// paths of TreeWarp (core/tree_warp_internal.h), each lane the scalar code's
// IEEE operations and integer look-ups in core/tree_warp.cc, so their bits
// are the scalar path's. Run only where math::Runs(VectorPath::kAvx512).
#include <immintrin.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>

#include "core/tree_warp_internal.h"

namespace sfc::tree_warp_internal {
namespace {

// std::clamp(v, 0, kBelowOne), lane by lane.
inline __m512d ClampBelowOne(__m512d v) {
  const __m512d zero = _mm512_setzero_pd(), below_one = _mm512_set1_pd(kBelowOne);
  const __m512d r = _mm512_mask_mov_pd(v, _mm512_cmp_pd_mask(below_one, v, _CMP_LT_OQ), below_one);
  return _mm512_mask_mov_pd(r, _mm512_cmp_pd_mask(v, zero, _CMP_LT_OQ), zero);
}

}  // namespace

// Descend<2> (TreeWarp::Descend) for the points i < m in vectors of eight
// lanes on AVX-512F, each lane the scalar code's steps (Pick's compare,
// select, subtract, multiply and clamp; the nodes' entries gathered); lanes
// at their leaves are masked. Returns how many points it took (a multiple of
// eight, at most 64); the caller descends the rest.
size_t DescendGrid2Avx512(size_t m, double* a, double* b, int32_t* ref, uint8_t* state,
                          const double* splits, const int32_t* children, const int32_t* state_at) {
  const __m512d zero = _mm512_setzero_pd();
  const __m512i none = _mm512_setzero_si512(), one = _mm512_set1_epi64(1);
  // Up to 8 vectors side by side, a level each per round, so that their
  // gathers overlap.
  constexpr size_t kVectors = 8;
  const size_t vectors = std::min(m / 8, kVectors);
  __m512d va[kVectors], vb[kVectors];
  __m512i vref[kVectors], vstate[kVectors];
  for (size_t v = 0; v < vectors; ++v) {
    va[v] = _mm512_loadu_pd(a + 8 * v), vb[v] = _mm512_loadu_pd(b + 8 * v);
    vref[v] = _mm512_cvtepi32_epi64(_mm256_loadu_si256(reinterpret_cast<__m256i*>(ref + 8 * v)));
    vstate[v] = _mm512_cvtepu8_epi64(_mm_loadl_epi64(reinterpret_cast<__m128i*>(state + 8 * v)));
  }
  for (bool descending = vectors > 0; descending;) {
    descending = false;
    for (size_t v = 0; v < vectors; ++v) {
      const __mmask8 active = _mm512_cmpge_epi64_mask(vref[v], none);
      if (active == 0) continue;
      descending = true;
      // Node entries at ref * 12: the columns' bounds and inverse widths, then
      // each column's rows' (TreeWarp::splits_, grid 2).
      const __m512i node =
          _mm512_add_epi64(_mm512_slli_epi64(vref[v], 3), _mm512_slli_epi64(vref[v], 2));
      const __m512d column_bound = _mm512_mask_i64gather_pd(zero, active, node, splits, 8);
      const __mmask8 right = _mm512_cmp_pd_mask(va[v], column_bound, _CMP_GE_OQ);
      const __m512i dx = _mm512_maskz_mov_epi64(right, one);
      const __m512d column_inverse = _mm512_mask_i64gather_pd(
          zero, active, _mm512_add_epi64(node, _mm512_add_epi64(dx, _mm512_set1_epi64(2))), splits,
          8);
      const __m512d na = ClampBelowOne(_mm512_mul_pd(
          _mm512_sub_pd(va[v], _mm512_maskz_mov_pd(right, column_bound)), column_inverse));
      const __m512i rows =
          _mm512_add_epi64(node, _mm512_add_epi64(_mm512_slli_epi64(dx, 2), _mm512_set1_epi64(4)));
      const __m512d row_bound = _mm512_mask_i64gather_pd(zero, active, rows, splits, 8);
      const __mmask8 up = _mm512_cmp_pd_mask(vb[v], row_bound, _CMP_GE_OQ);
      const __m512i dy = _mm512_maskz_mov_epi64(up, one);
      const __m512d row_inverse = _mm512_mask_i64gather_pd(
          zero, active, _mm512_add_epi64(rows, _mm512_add_epi64(dy, _mm512_set1_epi64(2))), splits,
          8);
      const __m512d nb = ClampBelowOne(
          _mm512_mul_pd(_mm512_sub_pd(vb[v], _mm512_maskz_mov_pd(up, row_bound)), row_inverse));
      const __m512i at = _mm512_add_epi64(_mm512_slli_epi64(dy, 1), dx);
      const __m512i child = _mm512_cvtepi32_epi64(_mm512_mask_i64gather_epi32(
          _mm256_setzero_si256(), active, _mm512_add_epi64(_mm512_slli_epi64(vref[v], 2), at),
          children, 4));
      const __m512i next_state = _mm512_cvtepi32_epi64(_mm512_mask_i64gather_epi32(
          _mm256_setzero_si256(), active, _mm512_add_epi64(_mm512_slli_epi64(vstate[v], 2), at),
          state_at, 4));
      va[v] = _mm512_mask_mov_pd(va[v], active, na);
      vb[v] = _mm512_mask_mov_pd(vb[v], active, nb);
      vref[v] = _mm512_mask_mov_epi64(vref[v], active, child);
      vstate[v] = _mm512_mask_mov_epi64(vstate[v], active, next_state);
    }
  }
  for (size_t v = 0; v < vectors; ++v) {
    _mm512_storeu_pd(a + 8 * v, va[v]);
    _mm512_storeu_pd(b + 8 * v, vb[v]);
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(ref + 8 * v), _mm512_cvtepi64_epi32(vref[v]));
    _mm_storel_epi64(reinterpret_cast<__m128i*>(state + 8 * v), _mm512_cvtepi64_epi8(vstate[v]));
  }
  return 8 * vectors;
}

namespace {

// min(uint64(std::max(0.0, v) * cells), top) lane by lane, for v * cells <
// 2^32 (std::max keeps 0 unless 0 < v).
inline __m512i CellsOf(__m512d v, __m512d cells, __m512i top) {
  const __m512d zero = _mm512_setzero_pd();
  const __m512d kept = _mm512_mask_mov_pd(zero, _mm512_cmp_pd_mask(zero, v, _CMP_LT_OQ), v);
  const __m512i c = _mm512_cvtepu32_epi64(_mm512_cvttpd_epu32(_mm512_mul_pd(kept, cells)));
  return _mm512_min_epu64(c, top);
}

}  // namespace

// TreeWarp::DigitsInLeaf for a Hilbert tree (grid 2, chunks of 4 levels:
// encode's 16 x 16 cells) on AVX-512F, eight points to a vector: the same
// integer steps (the column and row by the same double product and
// truncation, each level's and chunk's look-ups gathered). Returns how many
// points it took (a multiple of eight); the caller encodes the rest.
size_t DigitsGrid2Avx512(size_t m, const double* x, const double* y, const uint8_t* state,
                         double cells, uint64_t top, int chunks, int head, const int32_t* child_at,
                         const int32_t* state_at, const uint64_t* encode, uint64_t* digits) {
  const __m512d scale = _mm512_set1_pd(cells);
  const __m512i top_v = _mm512_set1_epi64(static_cast<int64_t>(top));
  const __m512i low4 = _mm512_set1_epi64(15), low1 = _mm512_set1_epi64(1);
  const __m512i digit_mask = _mm512_set1_epi64(static_cast<int64_t>((uint64_t{1} << 56) - 1));
  size_t i0 = 0;
  for (; i0 + 8 <= m; i0 += 8) {
    const __m512i cx = CellsOf(_mm512_loadu_pd(x + i0), scale, top_v);
    const __m512i cy = CellsOf(_mm512_loadu_pd(y + i0), scale, top_v);
    __m512i s = _mm512_cvtepu8_epi64(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(state + i0)));
    __m512i d = _mm512_setzero_si512();
    // The leading levels, above the chunks, one at a time.
    for (int level = head - 1; level >= 0; --level) {
      const int shift = 4 * chunks + level;
      const __m512i dx = _mm512_and_si512(_mm512_srli_epi64(cx, shift), low1);
      const __m512i dy = _mm512_and_si512(_mm512_srli_epi64(cy, shift), low1);
      const __m512i at =
          _mm512_add_epi64(_mm512_add_epi64(_mm512_slli_epi64(s, 2), _mm512_slli_epi64(dy, 1)), dx);
      const __m512i child = _mm512_cvtepi32_epi64(_mm512_i64gather_epi32(at, child_at, 4));
      d = _mm512_add_epi64(_mm512_slli_epi64(d, 2), child);
      s = _mm512_cvtepi32_epi64(_mm512_i64gather_epi32(at, state_at, 4));
    }
    for (int c = chunks - 1; c >= 0; --c) {
      const __m512i xs = _mm512_and_si512(_mm512_srli_epi64(cx, 4 * c), low4);
      const __m512i ys = _mm512_and_si512(_mm512_srli_epi64(cy, 4 * c), low4);
      const __m512i cell =
          _mm512_add_epi64(_mm512_slli_epi64(s, 8), _mm512_add_epi64(_mm512_slli_epi64(ys, 4), xs));
      const __m512i e = _mm512_i64gather_epi64(cell, encode, 8);
      d = _mm512_add_epi64(_mm512_slli_epi64(d, 8), _mm512_and_si512(e, digit_mask));
      s = _mm512_srli_epi64(e, 56);
    }
    _mm512_storeu_si512(digits + i0, d);
  }
  return i0;
}

namespace {

// CdfInversion's F(x) = x (p0 + x (p1 / 2 + x (p2 / 3))), lane by lane.
inline __m512d CdfLanes(__m512d x, __m512d p0, __m512d half_p1, __m512d third_p2) {
  return _mm512_mul_pd(
      x, _mm512_add_pd(p0, _mm512_mul_pd(x, _mm512_add_pd(half_p1, _mm512_mul_pd(x, third_p2)))));
}

}  // namespace

// InvertCdfs on AVX-512F: the problems eight lanes to a vector, each lane
// CdfInversion::Step's operations (both of its branches computed, one
// selected; a lane that is done keeps its value), up to eight vectors a step
// each per round.
void InvertCdfsAvx512(size_t n, const uint8_t* lanes, const double (*p)[3], const double* share,
                      double* out) {
  constexpr size_t kMax = 64;
  alignas(64) double p0[kMax], p1[kMax], p2[kMax], sh[kMax], result[kMax];
  for (size_t j = 0; j < kMax; ++j) {  // the padding: a problem of its own, never read
    p0[j] = j < n ? p[lanes[j]][0] : 1.0;
    p1[j] = j < n ? p[lanes[j]][1] : 0.0;
    p2[j] = j < n ? p[lanes[j]][2] : 0.0;
    sh[j] = j < n ? share[lanes[j]] : 0.5;
  }
  const size_t vectors = (n + 7) / 8;
  const __m512d zero = _mm512_setzero_pd(), one = _mm512_set1_pd(1.0);
  const __m512d two = _mm512_set1_pd(2.0), three = _mm512_set1_pd(3.0);
  const __m512d tiny_step = _mm512_set1_pd(0x1.0p-44), tiny_bracket = _mm512_set1_pd(0x1.0p-52);
  __m512d c0[8], c1[8], c2[8], half_c1[8], third_c2[8], target[8], lo[8], hi[8], s[8];
  __mmask8 active[8];
  for (size_t v = 0; v < vectors; ++v) {
    c0[v] = _mm512_load_pd(p0 + 8 * v), c1[v] = _mm512_load_pd(p1 + 8 * v);
    c2[v] = _mm512_load_pd(p2 + 8 * v);
    half_c1[v] = _mm512_div_pd(c1[v], two), third_c2[v] = _mm512_div_pd(c2[v], three);
    const __m512d share_v = _mm512_load_pd(sh + 8 * v);
    target[v] = _mm512_mul_pd(share_v, CdfLanes(one, c0[v], half_c1[v], third_c2[v]));
    lo[v] = zero, hi[v] = one, s[v] = share_v;
    active[v] = 0xff;
  }
  for (int step = 0; step < kCdfMaxSteps; ++step) {
    bool any = false;
    for (size_t v = 0; v < vectors; ++v) {
      if (active[v] == 0) continue;
      any = true;
      const __m512d f = _mm512_sub_pd(CdfLanes(s[v], c0[v], half_c1[v], third_c2[v]), target[v]);
      const __mmask8 hit = _mm512_cmp_pd_mask(f, zero, _CMP_EQ_OQ);
      const __mmask8 moving = active[v] & ~hit;
      const __mmask8 above = _mm512_cmp_pd_mask(f, zero, _CMP_GT_OQ);
      const __m512d new_hi = _mm512_mask_mov_pd(hi[v], moving & above, s[v]);
      const __m512d new_lo = _mm512_mask_mov_pd(lo[v], moving & ~above, s[v]);
      const __m512d d = _mm512_add_pd(
          c0[v], _mm512_mul_pd(s[v], _mm512_add_pd(c1[v], _mm512_mul_pd(s[v], c2[v]))));
      const __m512d middle = _mm512_div_pd(_mm512_add_pd(new_lo, new_hi), two);
      __m512d next = _mm512_mask_mov_pd(middle, _mm512_cmp_pd_mask(d, zero, _CMP_GT_OQ),
                                        _mm512_sub_pd(s[v], _mm512_div_pd(f, d)));
      const __mmask8 inside = _mm512_cmp_pd_mask(next, new_lo, _CMP_GT_OQ) &
                              _mm512_cmp_pd_mask(next, new_hi, _CMP_LT_OQ);
      next = _mm512_mask_mov_pd(middle, inside, next);
      const __mmask8 converged =
          _mm512_cmp_pd_mask(_mm512_abs_pd(_mm512_sub_pd(next, s[v])), tiny_step, _CMP_LE_OQ) |
          _mm512_cmp_pd_mask(_mm512_sub_pd(new_hi, new_lo), tiny_bracket, _CMP_LE_OQ);
      lo[v] = _mm512_mask_mov_pd(lo[v], moving, new_lo);
      hi[v] = _mm512_mask_mov_pd(hi[v], moving, new_hi);
      s[v] = _mm512_mask_mov_pd(s[v], moving, next);
      active[v] = moving & ~converged;
    }
    if (!any) break;
  }
  for (size_t v = 0; v < vectors; ++v) _mm512_store_pd(result + 8 * v, s[v]);
  for (size_t j = 0; j < n; ++j) out[lanes[j]] = result[j];
}

}  // namespace sfc::tree_warp_internal
