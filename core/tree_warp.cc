#include "core/tree_warp.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <functional>
#include <immintrin.h>

#include "core/leaf_model.h"

namespace sfc {
namespace {

// The orientations a curve's cells take: the 8 symmetries of the square.
constexpr int kStates = 8;

// The largest double below 1: a rescaled coordinate stays in [0, 1).
constexpr double kBelowOne = 1.0 - 0x1.0p-53;

// Picks among `n` parts with masses `mass` (not all zero) by the coordinate
// *a in [0, 1): the part holding a x total, with *a rescaled to that part
// (the inverse CDF of the parts, then of the uniform inside one). Zero-mass
// parts are never picked. Used where no bounds are stored (inside leaves).
int Split(const double* mass, int n, double* a) {
  double total = 0;
  for (int i = 0; i < n; ++i) total += mass[i];
  const double t = *a * total;
  double before = 0;
  int last = -1;
  for (int i = 0; i < n; ++i) {
    if (!(mass[i] > 0)) continue;
    last = i;
    if (before + mass[i] > t) break;
    before += mass[i];
  }
  assert(last >= 0);
  *a = std::clamp((t - before) / mass[last], 0.0, kBelowOne);
  return last;
}

// The bounds and inverse widths of parts with masses `mass` (Split's choice
// as stored bounds): bound[i] the cumulative share up to part i, 1 from the
// last part with mass on, so a < 1 always finds a part with mass.
void Bounds(const double* mass, int n, double* bound, double* inverse) {
  double total = 0;
  for (int i = 0; i < n; ++i) total += mass[i];
  int last = 0;
  for (int i = 0; i < n; ++i) {
    if (mass[i] > 0) last = i;
  }
  double before = 0;
  for (int i = 0; i < n; ++i) {
    before += mass[i];
    bound[i] = i >= last || !(total > 0) ? 1.0 : before / total;
    inverse[i] = mass[i] > 0 ? total / mass[i] : 0;
  }
}

// The part of stored bounds that a falls in, and a rescaled to it.
int Pick(const double* bound, const double* inverse, int n, double* a) {
  // The count of bounds at or below a, without branches: bounds do not
  // decrease, and the last is 1 > a.
  int i = 0;
  for (int j = 0; j + 1 < n; ++j) i += *a >= bound[j];
  const double lower = i == 0 ? 0.0 : bound[i - 1];
  *a = std::clamp((*a - lower) * inverse[i], 0.0, kBelowOne);
  return i;
}

// std::clamp(v, 0, kBelowOne), lane by lane.
__attribute__((target("avx512f"))) inline __m512d ClampBelowOne(__m512d v) {
  const __m512d zero = _mm512_setzero_pd(), below_one = _mm512_set1_pd(kBelowOne);
  const __m512d r = _mm512_mask_mov_pd(v, _mm512_cmp_pd_mask(below_one, v, _CMP_LT_OQ), below_one);
  return _mm512_mask_mov_pd(r, _mm512_cmp_pd_mask(v, zero, _CMP_LT_OQ), zero);
}

// Descend<2> (TreeWarp::Descend) for the points i < m in vectors of eight
// lanes on AVX-512F, each lane the scalar code's steps (Pick's compare,
// select, subtract, multiply and clamp; the nodes' entries gathered); lanes
// at their leaves are masked. Returns how many points it took (a multiple of
// eight, at most 64); the caller descends the rest.
__attribute__((target("avx512f"))) size_t DescendGrid2Avx512(size_t m, double* a, double* b,
                                                             int32_t* ref, uint8_t* state,
                                                             const double* splits,
                                                             const int32_t* children,
                                                             const int32_t* state_at) {
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
    vstate[v] =
        _mm512_cvtepu8_epi64(_mm_loadl_epi64(reinterpret_cast<__m128i*>(state + 8 * v)));
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

// p(s) = p0 + p1 s + p2 s^2 >= 0 on [0, 1].
bool NotNegative(double p0, double p1, double p2) {
  if (p0 < 0 || p0 + p1 + p2 < 0) return false;
  if (p2 > 0) {
    const double s = -p1 / (2 * p2);
    if (s > 0 && s < 1 && p0 + s * (p1 + s * p2) < 0) return false;
  }
  return true;
}

// The s in [0, 1] where the CDF F(s) = p0 s + p1 s^2 / 2 + p2 s^3 / 3 of a
// density p not negative on [0, 1] reaches `share` of F(1): Newton's method
// kept inside a shrinking bracket (bisection where a step leaves it). One
// problem's state, so that a batch can take its steps side by side.
class CdfInversion {
 public:
  CdfInversion() = default;
  CdfInversion(const double p[3], double share)
      : p0_(p[0]), p1_(p[1]), p2_(p[2]), target_(share * Cdf(1)), s_(share) {}
  // One step; true when done, with the answer in s().
  bool Step() {
    const double f = Cdf(s_) - target_;
    if (f == 0) return true;
    if (f > 0) {
      hi_ = s_;
    } else {
      lo_ = s_;
    }
    const double d = p0_ + s_ * (p1_ + s_ * p2_);
    double next = d > 0 ? s_ - f / d : (lo_ + hi_) / 2;
    if (!(next > lo_ && next < hi_)) next = (lo_ + hi_) / 2;
    // A step below 2^-44 of the leaf is far below the address's 2^-26
    // (Hilbert; 3^-16 for the 3x3 curves) resolution.
    const bool done = std::fabs(next - s_) <= 0x1.0p-44 || hi_ - lo_ <= 0x1.0p-52;
    s_ = next;
    return done;
  }
  double s() const { return s_; }
  static constexpr int kMaxSteps = 100;  // then s() as it stands

 private:
  double Cdf(double s) const { return s * (p0_ + s * (p1_ / 2 + s * (p2_ / 3))); }
  double p0_ = 0, p1_ = 0, p2_ = 0, target_ = 0;
  double lo_ = 0, hi_ = 1, s_ = 0;
};

double InvertCdf(const double p[3], double share) {
  CdfInversion inversion(p, share);
  for (int step = 0; step < CdfInversion::kMaxSteps && !inversion.Step(); ++step) {
  }
  return inversion.s();
}

// InvertCdf(p[i], share[i]) into out[i] for the n <= 64 problems listed in
// lanes, their steps taken side by side (each its own InvertCdf's steps).
// min(uint64(std::max(0.0, v) * cells), top) lane by lane, for v * cells <
// 2^32 (std::max keeps 0 unless 0 < v).
__attribute__((target("avx512f"))) inline __m512i CellsOf(__m512d v, __m512d cells,
                                                          __m512i top) {
  const __m512d zero = _mm512_setzero_pd();
  const __m512d kept = _mm512_mask_mov_pd(zero, _mm512_cmp_pd_mask(zero, v, _CMP_LT_OQ), v);
  const __m512i c = _mm512_cvtepu32_epi64(_mm512_cvttpd_epu32(_mm512_mul_pd(kept, cells)));
  return _mm512_min_epu64(c, top);
}

// TreeWarp::DigitsInLeaf for a Hilbert tree (grid 2, chunks of 4 levels:
// encode's 16 x 16 cells) on AVX-512F, eight points to a vector: the same
// integer steps (the column and row by the same double product and
// truncation, each level's and chunk's look-ups gathered). Returns how many
// points it took (a multiple of eight); the caller encodes the rest.
__attribute__((target("avx512f"))) size_t DigitsGrid2Avx512(
    size_t m, const double* x, const double* y, const uint8_t* state, double cells,
    uint64_t top, int chunks, int head, const int32_t* child_at, const int32_t* state_at,
    const uint64_t* encode, uint64_t* digits) {
  const __m512d scale = _mm512_set1_pd(cells);
  const __m512i top_v = _mm512_set1_epi64(static_cast<int64_t>(top));
  const __m512i low4 = _mm512_set1_epi64(15), low1 = _mm512_set1_epi64(1);
  const __m512i digit_mask = _mm512_set1_epi64(static_cast<int64_t>((uint64_t{1} << 56) - 1));
  size_t i0 = 0;
  for (; i0 + 8 <= m; i0 += 8) {
    const __m512i cx = CellsOf(_mm512_loadu_pd(x + i0), scale, top_v);
    const __m512i cy = CellsOf(_mm512_loadu_pd(y + i0), scale, top_v);
    __m512i s =
        _mm512_cvtepu8_epi64(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(state + i0)));
    __m512i d = _mm512_setzero_si512();
    // The leading levels, above the chunks, one at a time.
    for (int level = head - 1; level >= 0; --level) {
      const int shift = 4 * chunks + level;
      const __m512i dx = _mm512_and_si512(_mm512_srli_epi64(cx, shift), low1);
      const __m512i dy = _mm512_and_si512(_mm512_srli_epi64(cy, shift), low1);
      const __m512i at = _mm512_add_epi64(_mm512_add_epi64(_mm512_slli_epi64(s, 2),
                                                           _mm512_slli_epi64(dy, 1)),
                                          dx);
      const __m512i child = _mm512_cvtepi32_epi64(_mm512_i64gather_epi32(at, child_at, 4));
      d = _mm512_add_epi64(_mm512_slli_epi64(d, 2), child);
      s = _mm512_cvtepi32_epi64(_mm512_i64gather_epi32(at, state_at, 4));
    }
    for (int c = chunks - 1; c >= 0; --c) {
      const __m512i xs = _mm512_and_si512(_mm512_srli_epi64(cx, 4 * c), low4);
      const __m512i ys = _mm512_and_si512(_mm512_srli_epi64(cy, 4 * c), low4);
      const __m512i cell = _mm512_add_epi64(
          _mm512_slli_epi64(s, 8), _mm512_add_epi64(_mm512_slli_epi64(ys, 4), xs));
      const __m512i e = _mm512_i64gather_epi64(cell, encode, 8);
      d = _mm512_add_epi64(_mm512_slli_epi64(d, 8), _mm512_and_si512(e, digit_mask));
      s = _mm512_srli_epi64(e, 56);
    }
    _mm512_storeu_si512(digits + i0, d);
  }
  return i0;
}

// CdfInversion's F(x) = x (p0 + x (p1 / 2 + x (p2 / 3))), lane by lane.
__attribute__((target("avx512f"))) inline __m512d CdfLanes(__m512d x, __m512d p0,
                                                           __m512d half_p1, __m512d third_p2) {
  return _mm512_mul_pd(
      x, _mm512_add_pd(p0, _mm512_mul_pd(x, _mm512_add_pd(half_p1, _mm512_mul_pd(x, third_p2)))));
}

// InvertCdfs on AVX-512F: the problems eight lanes to a vector, each lane
// CdfInversion::Step's operations (both of its branches computed, one
// selected; a lane that is done keeps its value), up to eight vectors a step
// each per round.
__attribute__((target("avx512f"))) void InvertCdfsAvx512(size_t n, const uint8_t* lanes,
                                                         const double (*p)[3],
                                                         const double* share, double* out) {
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
  for (int step = 0; step < CdfInversion::kMaxSteps; ++step) {
    bool any = false;
    for (size_t v = 0; v < vectors; ++v) {
      if (active[v] == 0) continue;
      any = true;
      const __m512d f =
          _mm512_sub_pd(CdfLanes(s[v], c0[v], half_c1[v], third_c2[v]), target[v]);
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

void InvertCdfs(size_t n, const uint8_t* lanes, const double (*p)[3], const double* share,
                double* out, math::VectorPath path) {
  if (path == math::VectorPath::kAvx512) {
    InvertCdfsAvx512(n, lanes, p, share, out);
    return;
  }
  CdfInversion inversion[64];
  uint8_t active[64];
  size_t count = 0;
  for (size_t j = 0; j < n; ++j) {
    inversion[j] = CdfInversion(p[lanes[j]], share[lanes[j]]);
    active[count++] = static_cast<uint8_t>(j);
  }
  for (int step = 0; step < CdfInversion::kMaxSteps && count > 0; ++step) {
    size_t still = 0;
    for (size_t c = 0; c < count; ++c) {
      if (!inversion[active[c]].Step()) active[still++] = active[c];
    }
    count = still;
  }
  for (size_t j = 0; j < n; ++j) out[lanes[j]] = inversion[j].s();
}

// The quadratic factor of a Lagrange combination sum_i w[i] L_i(s) as
// coefficients of 1, s, s^2.
void PolynomialOf(const double w[3], double p[3]) {
  const auto& k = leaf_model_internal::kBasisTable.k;
  p[0] = w[0] * k[0][0] + w[1] * k[1][0] + w[2] * k[2][0];
  p[1] = w[0] * k[0][1] + w[1] * k[1][1] + w[2] * k[2][1];
  p[2] = w[0] * k[0][2] + w[1] * k[1][2] + w[2] * k[2][2];
}

// The marginal density of s of a quadratic model in its warped coordinates
// (s, t): sum_i L_i(s) sum_j c_ij int L_j, and int_0^1 L_j is the Gauss
// weight w_j. False where it dips below zero on [0, 1].
bool MarginalOf(const LeafModel& model, double p[3]) {
  double marginal[3];
  for (int i = 0; i < 3; ++i) {
    marginal[i] = 0;
    for (int j = 0; j < 3; ++j) marginal[i] += model.c[3 * i + j] * kGaussWeight[j];
  }
  PolynomialOf(marginal, p);
  return NotNegative(p[0], p[1], p[2]);
}

// The density of t at s: sum_j L_j(t) sum_i c_ij L_i(s). False where it dips
// below zero on [0, 1] or has no mass.
bool ConditionalOf(const LeafModel& model, double s, double q[3]) {
  using leaf_model_internal::Basis;
  double basis_s[3], conditional[3];
  for (int i = 0; i < 3; ++i) basis_s[i] = Basis(i, s);
  for (int j = 0; j < 3; ++j) {
    conditional[j] = 0;
    for (int i = 0; i < 3; ++i) conditional[j] += model.c[3 * i + j] * basis_s[i];
  }
  PolynomialOf(conditional, q);
  return NotNegative(q[0], q[1], q[2]) && q[0] + q[1] / 2 + q[2] / 3 > 0;
}

// Exact marginal-then-conditional inverse CDF of a quadratic model in its
// warped coordinates (s, t); false where the quadratic dips below zero on the
// cell (the caller then splits the clamped model's sub-squares).
bool PlaceQuadratic(const LeafModel& model, double a, double b, double* s, double* t) {
  double p[3], q[3];
  if (!MarginalOf(model, p)) return false;
  *s = InvertCdf(p, a);
  if (!ConditionalOf(model, *s, q)) return false;
  *t = InvertCdf(q, b);
  return true;
}

// Leaf coordinate of the point at x of the sub-cell [x0, x0 + side] of the
// coordinates ComputeGridFactors used: those warped by a blowing-up power law
// map back through it; along a vanishing one they were the leaf's own, and
// the point is uniform in warped coordinates inside the sub-cell (the model's
// own measure there), as core/leaf_walk.cc places it.
double OnAxis(const AxisWarp& w, double x0, double side, double x) {
  if (w.power == 1) return x;
  if (DescendsWarped(w)) return Warp(w, x);
  const double s0 = Unwarp(w, x0), s1 = Unwarp(w, x0 + side);
  return std::clamp(Warp(w, s0 + (x - x0) / side * (s1 - s0)), x0, x0 + side);
}

}  // namespace

TreeWarp::TreeWarp(const CurveTree& tree)
    : tree_(tree), curve_(tree.curve()), grid_(curve_.grid()), arity_(curve_.arity()) {
  child_at_.assign(kStates * arity_, 0);
  for (int s = 0; s < kStates; ++s) {
    for (int c = 0; c < arity_; ++c) {
      const Curve::Child& ch = curve_.ChildOf(s, c);
      child_at_[s * arity_ + ch.dy * grid_ + ch.dx] = c;
    }
  }
  state_at_.assign(kStates * arity_, 0);
  for (int s = 0; s < kStates; ++s) {
    for (int at = 0; at < arity_; ++at) {
      state_at_[s * arity_ + at] = curve_.ChildOf(s, child_at_[s * arity_ + at]).state;
    }
  }
  // Depth-first over the cells down to the leaves, which come in curve
  // order; a node's child masses are differences of the running sums.
  size_t next_leaf = 0;
  std::vector<double> masses;  // per node, by position, like children_
  std::function<int32_t(int, uint64_t, int)> build = [&](int depth, uint64_t start,
                                                         int state) -> int32_t {
    if (tree.leaf_start(next_leaf) == start && tree.leaf_depth(next_leaf) == depth) {
      return -static_cast<int32_t>(next_leaf++) - 1;
    }
    const int32_t node = static_cast<int32_t>(children_.size() / arity_);
    children_.resize(children_.size() + arity_);
    masses.resize(masses.size() + arity_);
    for (int c = 0; c < arity_; ++c) {
      const Curve::Child& ch = curve_.ChildOf(state, c);
      const size_t first = next_leaf;
      const int32_t child = build(depth + 1, start + c * curve_.Span(depth + 1), ch.state);
      const int at = node * arity_ + ch.dy * grid_ + ch.dx;
      children_[at] = child;
      masses[at] = tree.mass_end(next_leaf - 1) - tree.mass_begin(first);
    }
    return node;
  };
  root_ = build(0, 0, Curve::kRootState);
  assert(next_leaf == tree.leaf_count());
  // Each node's columns and rows as stored bounds.
  const int g = grid_;
  stride_ = 2 * (g + g * g);
  const size_t nodes = children_.size() / arity_;
  splits_.resize(nodes * stride_);
  for (size_t node = 0; node < nodes; ++node) {
    const double* mass = &masses[node * arity_];
    double* out = &splits_[node * stride_];
    double column[3] = {0, 0, 0};
    for (int dy = 0; dy < g; ++dy) {
      for (int dx = 0; dx < g; ++dx) column[dx] += mass[dy * g + dx];
    }
    Bounds(column, g, out, out + g);
    for (int dx = 0; dx < g; ++dx) {
      double row[3];
      for (int dy = 0; dy < g; ++dy) row[dy] = mass[dy * g + dx];
      Bounds(row, g, out + 2 * g + 2 * g * dx, out + 2 * g + 2 * g * dx + g);
    }
  }
  // The encoding table: every chunk of levels from every orientation.
  chunk_levels_ = g == 2 ? 4 : 2;
  chunk_cells_ = g == 2 ? 16 : 9;
  const int cells = chunk_cells_ * chunk_cells_;
  encode_.assign(kStates * cells, 0);
  for (int s0 = 0; s0 < kStates; ++s0) {
    for (int y = 0; y < chunk_cells_; ++y) {
      for (int x = 0; x < chunk_cells_; ++x) {
        uint64_t digits = 0;
        int state = s0, place = chunk_cells_ / g;
        for (int level = 0; level < chunk_levels_; ++level, place /= g) {
          const int c = child_at_[state * arity_ + (y / place % g) * g + x / place % g];
          digits = digits * arity_ + c;
          state = curve_.ChildOf(state, c).state;
        }
        encode_[s0 * cells + y * chunk_cells_ + x] = digits | (uint64_t(state) << 56);
      }
    }
  }
}

template <int G>
void TreeWarp::Descend(size_t m, double* a, double* b, int32_t* ref, uint8_t* state) const {
  // One level of every point still above its leaf per round.
  constexpr int kArity = G * G, kStride = 2 * (G + G * G);
  for (bool descending = true; descending;) {
    descending = false;
    for (size_t i = 0; i < m; ++i) {
      if (ref[i] < 0) continue;
      const double* split = &splits_[ref[i] * kStride];
      const int dx = Pick(split, split + G, G, &a[i]);
      const double* rows = split + 2 * G + 2 * G * dx;
      const int dy = Pick(rows, rows + G, G, &b[i]);
      const int at = dy * G + dx;
      ref[i] = children_[ref[i] * kArity + at];
      state[i] = static_cast<uint8_t>(state_at_[state[i] * kArity + at]);
      descending |= ref[i] >= 0;
    }
  }
}

void TreeWarp::LocateMany(size_t n, const double* a_in, const double* b_in, CurveAddress* out,
                          math::VectorPath path) const {
  constexpr size_t kBatch = 64;
  double a[kBatch], b[kBatch];
  int32_t ref[kBatch];
  uint8_t state[kBatch];
  for (size_t i0 = 0; i0 < n; i0 += kBatch) {
    const size_t m = std::min(kBatch, n - i0);
    for (size_t i = 0; i < m; ++i) {
      a[i] = std::clamp(a_in[i0 + i], 0.0, kBelowOne);
      b[i] = std::clamp(b_in[i0 + i], 0.0, kBelowOne);
      ref[i] = root_;
      state[i] = Curve::kRootState;
    }
    if (grid_ == 2) {
      const size_t vectored =
          path == math::VectorPath::kAvx512
              ? DescendGrid2Avx512(m, a, b, ref, state, splits_.data(), children_.data(),
                                   state_at_.data())
              : 0;
      Descend<2>(m - vectored, a + vectored, b + vectored, ref + vectored, state + vectored);
    } else {
      Descend<3>(m, a, b, ref, state);
    }
    // The leaves' models lie anywhere in memory: fetched a few points ahead.
    constexpr size_t kAhead = 8;
    for (size_t i = 0; i < std::min(m, kAhead); ++i) {
      __builtin_prefetch(&tree_.leaf_model(static_cast<size_t>(-ref[i] - 1)));
    }
    double x[kBatch], y[kBatch];
    uint64_t digits[kBatch];
    // Quadratic leaves: each inverse CDF over the batch side by side; the
    // others (and a quadratic that dips below zero) one at a time.
    double p[kBatch][3], s[kBatch], t[kBatch];
    uint8_t lanes[kBatch];
    size_t quadratic = 0;
    for (size_t i = 0; i < m; ++i) {
      if (i + kAhead < m) {
        __builtin_prefetch(&tree_.leaf_model(static_cast<size_t>(-ref[i + kAhead] - 1)));
      }
      const size_t l = static_cast<size_t>(-ref[i] - 1);
      if (tree_.leaf_model_kind(l) == LeafModel::Kind::kQuadratic &&
          MarginalOf(tree_.leaf_model(l), p[i])) {
        lanes[quadratic++] = static_cast<uint8_t>(i);
      }
    }
    InvertCdfs(quadratic, lanes, p, a, s, path);
    size_t conditional = 0;
    for (size_t j = 0; j < quadratic; ++j) {
      const size_t i = lanes[j];
      if (ConditionalOf(tree_.leaf_model(static_cast<size_t>(-ref[i] - 1)), s[i], p[i])) {
        lanes[conditional++] = static_cast<uint8_t>(i);
      }
    }
    InvertCdfs(conditional, lanes, p, b, t, path);
    for (size_t i = 0, j = 0; i < m; ++i) {
      const size_t l = static_cast<size_t>(-ref[i] - 1);
      if (j < conditional && lanes[j] == i) {  // PlaceInLeaf's quadratic case
        const LeafModel& model = tree_.leaf_model(l);
        x[i] = Warp(model.warp[0], s[i]);
        y[i] = Warp(model.warp[1], t[i]);
        ++j;
      } else {
        PlaceInLeaf(l, a[i], b[i], &x[i], &y[i]);
      }
    }
    DigitsInLeaf(m, x, y, state, digits, path);
    for (size_t i = 0; i < m; ++i) {
      CurveAddress& address = out[i0 + i];
      address.leaf = static_cast<uint32_t>(-ref[i] - 1);
      address.digits = digits[i];
      address.index = 0;
    }
  }
}

void TreeWarp::PlaceMany(size_t n, const CurveAddress* at, double* u, double* v,
                         double* curve_position) const {
  constexpr size_t kBatch = 64;
  uint64_t digits[kBatch], states[kBatch], cx[kBatch], cy[kBatch];
  const int levels = curve_.continuation_levels();
  const double cells = curve_.PowG(levels);
  const double digit_span = static_cast<double>(curve_.PowW(levels));
  const double curve_span = static_cast<double>(curve_.Span(0));
  double u0[kBatch], v0[kBatch], side[kBatch];
  size_t leaf = SIZE_MAX;  // the leaf whose cell is decoded
  CurveTree::Cell cell{};
  for (size_t i0 = 0; i0 < n; i0 += kBatch) {
    const size_t m = std::min(kBatch, n - i0);
    for (size_t i = 0; i < m; ++i) {
      if (at[i0 + i].leaf != leaf) leaf = at[i0 + i].leaf, cell = tree_.LeafCell(leaf);
      u0[i] = cell.u0, v0[i] = cell.v0;
      side[i] = cell.size / cells;
      digits[i] = at[i0 + i].digits;
      states[i] = static_cast<uint64_t>(cell.state);
    }
    curve_.DescendMany(digits, levels, m, states, cx, cy);
    for (size_t i = 0; i < m; ++i) {
      // The centre of the sub-cell, as LeafWalk::Continue computes it.
      u[i0 + i] = u0[i] + (static_cast<double>(cx[i]) + 0.5) * side[i];
      v[i0 + i] = v0[i] + (static_cast<double>(cy[i]) + 0.5) * side[i];
      if (curve_position == nullptr) continue;
      const size_t l = at[i0 + i].leaf;
      const double start = static_cast<double>(tree_.leaf_start(l));
      const double span = static_cast<double>(tree_.leaf_end(l) - tree_.leaf_start(l));
      const double fraction = static_cast<double>(digits[i]) / digit_span;
      curve_position[i0 + i] = (start + fraction * span) / curve_span;
    }
  }
}

void TreeWarp::PlaceInLeaf(size_t l, double a, double b, double* x, double* y) const {
  const LeafModel& model = tree_.leaf_model(l);
  const LeafModel::Kind kind = tree_.leaf_model_kind(l);
  if (kind == LeafModel::Kind::kQuadratic) {
    double s, t;
    if (PlaceQuadratic(model, a, b, &s, &t)) {
      *x = Warp(model.warp[0], s);
      *y = Warp(model.warp[1], t);
      return;
    }
  }
  // The clamped sub-square integrals: the piecewise model's own pieces, or
  // the finest table of a leaf walk for a quadratic that dips below zero.
  const bool quadratic = kind == LeafModel::Kind::kQuadratic;
  const int n = quadratic ? static_cast<int>(curve_.PowG(curve_.table_levels())) : grid_;
  GridFactors factors;
  ComputeGridFactors(model, kind, grid_, 0, 0, 1, n, &factors);
  double column[kMaxGridCells], cells[kMaxGridCells];
  for (int i = 0; i < n; ++i) {
    column[i] = 0;
    for (int j = 0; j < n; ++j) column[i] += std::max(0.0, factors.Integral(i, j));
  }
  double total = 0;
  for (int i = 0; i < n; ++i) total += column[i];
  if (!(total > 0)) {  // the model vanishes: uniform over the leaf
    *x = a, *y = b;
    return;
  }
  const int i = Split(column, n, &a);
  for (int j = 0; j < n; ++j) cells[j] = std::max(0.0, factors.Integral(i, j));
  const int j = Split(cells, n, &b);
  const double side = 1.0 / n;
  *x = (i + a) * side, *y = (j + b) * side;
  if (quadratic) {
    *x = OnAxis(model.warp[0], i * side, side, *x);
    *y = OnAxis(model.warp[1], j * side, side, *y);
  }
}

void TreeWarp::DigitsInLeaf(size_t m, const double* x, const double* y, const uint8_t* state,
                            uint64_t* digits, math::VectorPath path) const {
  // The sub-cell's column and row among g^levels, then their base-g digits
  // a chunk at a time, from the top; each level over all m points before the
  // next, so the points' chains of table look-ups overlap.
  constexpr size_t kMax = 64;
  assert(m <= kMax);
  const int levels = curve_.continuation_levels();
  const double cells = curve_.PowG(levels);
  const uint64_t top = static_cast<uint64_t>(cells) - 1;
  const int chunks = levels / chunk_levels_, head = levels % chunk_levels_;
  if (grid_ == 2 && path == math::VectorPath::kAvx512) {
    const size_t vectored = DigitsGrid2Avx512(m, x, y, state, cells, top, chunks, head,
                                              child_at_.data(), state_at_.data(), encode_.data(),
                                              digits);
    x += vectored, y += vectored, state += vectored, digits += vectored, m -= vectored;
  }
  // Chunk values of each point's column and row, least significant first
  // (constant divisors: 16 for Hilbert, 9 for the 3x3 curves); what is left
  // are the leading levels.
  uint8_t xs[32][kMax], ys[32][kMax];
  uint64_t cx[kMax], cy[kMax];
  int s[kMax];
  for (size_t i = 0; i < m; ++i) {
    cx[i] = std::min(static_cast<uint64_t>(std::max(0.0, x[i]) * cells), top);
    cy[i] = std::min(static_cast<uint64_t>(std::max(0.0, y[i]) * cells), top);
    if (grid_ == 2) {
      for (int c = 0; c < chunks; ++c) {
        xs[c][i] = static_cast<uint8_t>(cx[i] & 15), cx[i] >>= 4;
        ys[c][i] = static_cast<uint8_t>(cy[i] & 15), cy[i] >>= 4;
      }
    } else {
      for (int c = 0; c < chunks; ++c) {
        xs[c][i] = static_cast<uint8_t>(cx[i] % 9), cx[i] /= 9;
        ys[c][i] = static_cast<uint8_t>(cy[i] % 9), cy[i] /= 9;
      }
    }
    digits[i] = 0;
    s[i] = state[i];
  }
  // The leading levels one at a time.
  uint64_t place = static_cast<uint64_t>(curve_.PowG(head));
  for (int level = 0; level < head; ++level) {
    place /= grid_;
    for (size_t i = 0; i < m; ++i) {
      const int dx = static_cast<int>(cx[i] / place % grid_);
      const int dy = static_cast<int>(cy[i] / place % grid_);
      const int c = child_at_[s[i] * arity_ + dy * grid_ + dx];
      digits[i] = digits[i] * arity_ + c;
      s[i] = curve_.ChildOf(s[i], c).state;
    }
  }
  const int cells_per_chunk = chunk_cells_ * chunk_cells_;
  const uint64_t chunk_span = curve_.PowW(chunk_levels_);
  for (int c = chunks - 1; c >= 0; --c) {
    for (size_t i = 0; i < m; ++i) {
      const uint64_t e = encode_[s[i] * cells_per_chunk + ys[c][i] * chunk_cells_ + xs[c][i]];
      digits[i] = digits[i] * chunk_span + (e & ((uint64_t{1} << 56) - 1));
      s[i] = static_cast<int>(e >> 56);
    }
  }
}

}  // namespace sfc
