// The tree warp's vector loops (core/tree_warp_internal.h), kLanes at a time
// in generic vectors (core/vector_lanes.h): each lane does the scalar code's
// IEEE operations in its order and its integer look-ups (comparisons and
// selects for its branches and clamps; the build has -ffp-contract=off), so
// every instruction set gives the bits of the scalar code in
// core/tree_warp.cc. tree_warp_avx2.cc builds them for AVX2 (four lanes, the
// kAvx2 path) and tree_warp_avx512.cc for AVX-512F (eight lanes, the kAvx512
// path); TreeWarp dispatches on its vector path. Internal linkage on purpose
// (an anonymous namespace): each of the two files keeps its own copy,
// compiled for its instruction set.
//
// Thread-safety: pure functions.
#ifndef SFCSAMPLER_CORE_TREE_WARP_LANES_H_
#define SFCSAMPLER_CORE_TREE_WARP_LANES_H_

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "core/tree_warp_internal.h"
#include "core/vector_lanes.h"

namespace sfc::tree_warp_internal {
namespace {

using vector_lanes::Any;
using vector_lanes::Doubles;
using vector_lanes::Gather;
using vector_lanes::GatherWhere;
using vector_lanes::Int32s;
using vector_lanes::Ints;
using vector_lanes::kLanes;
using vector_lanes::LoadBytes;
using vector_lanes::LoadInt32s;
using vector_lanes::StoreNarrowed;
using vector_lanes::Widen;
using vector_lanes::Words;

// TreeWarp's batch: at most this many points, in this many vectors.
constexpr size_t kMaxPoints = 64, kVectors = kMaxPoints / kLanes;

__attribute__((always_inline)) inline Doubles LoadDoubles(const double* p) {
  Doubles v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

// std::clamp(v, 0, kBelowOne), lane by lane.
__attribute__((always_inline)) inline Doubles ClampBelowOne(Doubles v) {
  const Doubles zero{}, below_one = zero + kBelowOne;
  const Doubles r = below_one < v ? below_one : v;
  return v < zero ? zero : r;
}

// Descend<2> (TreeWarp::Descend) for the points i < m, kLanes to a vector,
// each lane the scalar code's steps (Pick's compare, select, subtract,
// multiply and clamp; the nodes' entries gathered); lanes at their leaves
// are masked. Up to kVectors vectors side by side, a level each per round,
// so that their gathers overlap. Returns how many points it took (a
// multiple of kLanes, at most kMaxPoints); the caller descends the rest.
__attribute__((always_inline)) inline size_t DescendGrid2Lanes(size_t m, double* a, double* b,
                                                               int32_t* ref, uint8_t* state,
                                                               const double* splits,
                                                               const int32_t* children,
                                                               const int32_t* state_at) {
  const size_t vectors = std::min(m / kLanes, kVectors);
  Doubles va[kVectors], vb[kVectors];
  Ints vref[kVectors], vstate[kVectors];
  for (size_t v = 0; v < vectors; ++v) {
    va[v] = LoadDoubles(a + kLanes * v), vb[v] = LoadDoubles(b + kLanes * v);
    vref[v] = LoadInt32s(ref + kLanes * v), vstate[v] = LoadBytes(state + kLanes * v);
  }
  const Ints none{};
  for (bool descending = vectors > 0; descending;) {
    descending = false;
    for (size_t v = 0; v < vectors; ++v) {
      const Ints active = vref[v] >= none;
      if (!Any(active)) continue;
      descending = true;
      // Node entries at ref * 12: the columns' bounds and inverse widths, then
      // each column's rows' (TreeWarp::splits_, grid 2).
      const Ints node = (vref[v] << 3) + (vref[v] << 2);
      // One split, the column's (x at `at`) or the row's: the side x falls
      // on (d, 0 or 1) and x rescaled to it.
      auto pick = [&](Doubles x, Ints at, Ints* d) {
        const Doubles bound = GatherWhere(splits, at, active);
        const Ints beyond = x >= bound;
        *d = beyond & 1;
        const Doubles inverse = GatherWhere(splits, at + *d + 2, active);
        return ClampBelowOne((x - (beyond ? bound : Doubles{})) * inverse);
      };
      Ints dx, dy;
      const Doubles na = pick(va[v], node, &dx);
      const Doubles nb = pick(vb[v], node + (dx << 2) + 4, &dy);
      const Ints at = (dy << 1) + dx;
      const Ints child = GatherWhere(children, (vref[v] << 2) + at, active);
      const Ints next_state = GatherWhere(state_at, (vstate[v] << 2) + at, active);
      va[v] = active ? na : va[v];
      vb[v] = active ? nb : vb[v];
      vref[v] = active ? child : vref[v];
      vstate[v] = active ? next_state : vstate[v];
    }
  }
  for (size_t v = 0; v < vectors; ++v) {
    std::memcpy(a + kLanes * v, &va[v], sizeof(Doubles));
    std::memcpy(b + kLanes * v, &vb[v], sizeof(Doubles));
    StoreNarrowed(vref[v], ref + kLanes * v);
    StoreNarrowed(vstate[v], state + kLanes * v);
  }
  return kLanes * vectors;
}

// min(uint64(std::max(0.0, v) * cells), top) lane by lane, for v * cells <
// 2^31 and top < 2^31 (std::max keeps 0 unless 0 < v; the truncation is then
// the scalar conversion's).
__attribute__((always_inline)) inline Words CellsOf(Doubles v, Doubles cells, Int32s top) {
  const Doubles zero{};
  const Doubles kept = zero < v ? v : zero;
  const Int32s c = __builtin_convertvector(kept * cells, Int32s);
  return (Words)Widen(c < top ? c : top);
}

// TreeWarp::DigitsInLeaf for a Hilbert tree (grid 2, chunks of 4 levels:
// encode's 16 x 16 cells), kLanes points to a vector: the same integer steps
// (the column and row by the same double product and truncation, each
// level's and chunk's look-ups gathered). Returns how many points it took (a
// multiple of kLanes; none unless cells <= 2^30); the caller encodes the
// rest.
__attribute__((always_inline)) inline size_t DigitsGrid2Lanes(
    size_t m, const double* x, const double* y, const uint8_t* state, double cells, uint64_t top,
    int chunks, int head, const int32_t* child_at, const int32_t* state_at, const uint64_t* encode,
    uint64_t* digits) {
  if (!(cells <= 0x1.0p30)) return 0;
  const Doubles scale = Doubles{} + cells;
  const Int32s top_v = Int32s{} + static_cast<int32_t>(top);
  const uint64_t digit_mask = (uint64_t{1} << 56) - 1;
  size_t i0 = 0;
  for (; i0 + kLanes <= m; i0 += kLanes) {
    const Words cx = CellsOf(LoadDoubles(x + i0), scale, top_v);
    const Words cy = CellsOf(LoadDoubles(y + i0), scale, top_v);
    Ints s = LoadBytes(state + i0);
    Words d{};
    // The leading levels, above the chunks, one at a time.
    for (int level = head - 1; level >= 0; --level) {
      const int shift = 4 * chunks + level;
      const Ints at = (s << 2) + (Ints)((((cy >> shift) & 1) << 1) + ((cx >> shift) & 1));
      d = (d << 2) + (Words)Gather(child_at, at);
      s = Gather(state_at, at);
    }
    for (int c = chunks - 1; c >= 0; --c) {
      const Ints cell = (s << 8) + (Ints)((((cy >> (4 * c)) & 15) << 4) + ((cx >> (4 * c)) & 15));
      const Words e = Gather(encode, cell);
      d = (d << 8) + (e & digit_mask);
      s = (Ints)(e >> 56);
    }
    std::memcpy(digits + i0, &d, sizeof d);
  }
  return i0;
}

// CdfInversion's F(x) = x (p0 + x (p1 / 2 + x (p2 / 3))), lane by lane.
__attribute__((always_inline)) inline Doubles CdfLanes(Doubles x, Doubles p0, Doubles half_p1,
                                                       Doubles third_p2) {
  return x * (p0 + x * (half_p1 + x * third_p2));
}

// InvertCdfs: the problems kLanes to a vector, each lane CdfInversion::Step's
// operations (both of its branches computed, one selected; a lane that is
// done keeps its value), up to kVectors vectors a step each per round.
__attribute__((always_inline)) inline void InvertCdfsLanes(size_t n, const uint8_t* lanes,
                                                           const double (*p)[3],
                                                           const double* share, double* out) {
  // Each problem's density and its answer s, from its share; the padding is
  // a problem of its own, never read.
  alignas(64) double c0[kMaxPoints], c1[kMaxPoints], c2[kMaxPoints], s[kMaxPoints];
  for (size_t j = 0; j < kMaxPoints; ++j) {
    c0[j] = j < n ? p[lanes[j]][0] : 1.0;
    c1[j] = j < n ? p[lanes[j]][1] : 0.0;
    c2[j] = j < n ? p[lanes[j]][2] : 0.0;
    s[j] = j < n ? share[lanes[j]] : 0.5;
  }
  const size_t vectors = (n + kLanes - 1) / kLanes;
  const Doubles zero{}, one = zero + 1.0, two = zero + 2.0, three = zero + 3.0;
  const Doubles tiny_step = zero + 0x1.0p-44, tiny_bracket = zero + 0x1.0p-52;
  const Words magnitude = Words{} + ~(uint64_t{1} << 63);
  Doubles half_c1[kVectors], third_c2[kVectors], target[kVectors], lo[kVectors], hi[kVectors];
  Ints active[kVectors];
  for (size_t v = 0; v < vectors; ++v) {
    const size_t at = kLanes * v;
    half_c1[v] = LoadDoubles(c1 + at) / two, third_c2[v] = LoadDoubles(c2 + at) / three;
    target[v] = LoadDoubles(s + at) * CdfLanes(one, LoadDoubles(c0 + at), half_c1[v], third_c2[v]);
    lo[v] = zero, hi[v] = one, active[v] = Ints{} - 1;
  }
  for (int step = 0; step < kCdfMaxSteps; ++step) {
    bool any = false;
    for (size_t v = 0; v < vectors; ++v) {
      if (!Any(active[v])) continue;
      any = true;
      const size_t at = kLanes * v;
      const Doubles sv = LoadDoubles(s + at), p0 = LoadDoubles(c0 + at);
      const Doubles p1 = LoadDoubles(c1 + at), p2 = LoadDoubles(c2 + at);
      const Doubles f = CdfLanes(sv, p0, half_c1[v], third_c2[v]) - target[v];
      const Doubles d = p0 + sv * (p1 + sv * p2);
      const Doubles newton = sv - f / d;  // the division first: the longest wait
      const Ints moving = (f != zero) & active[v];
      const Ints above = f > zero;
      // Lanes that do not move keep their bracket.
      hi[v] = (moving & above) ? sv : hi[v];
      lo[v] = (moving & ~above) ? sv : lo[v];
      const Doubles middle = (lo[v] + hi[v]) / two;
      // Newton's step where d > 0 and it stays inside the bracket, else the
      // bisection (the scalar code's two tests, either of which gives it).
      const Doubles next = (d > zero) & (newton > lo[v]) & (newton < hi[v]) ? newton : middle;
      const Doubles step_size = (Doubles)((Words)(next - sv) & magnitude);
      const Ints converged = (step_size <= tiny_step) | (hi[v] - lo[v] <= tiny_bracket);
      const Doubles s_next = moving ? next : sv;
      std::memcpy(s + at, &s_next, sizeof s_next);
      active[v] = moving & ~converged;
    }
    if (!any) break;
  }
  for (size_t j = 0; j < n; ++j) out[lanes[j]] = s[j];
}

}  // namespace
}  // namespace sfc::tree_warp_internal

#endif  // SFCSAMPLER_CORE_TREE_WARP_LANES_H_
