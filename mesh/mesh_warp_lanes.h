// The mesh warp's batch loops (mesh/mesh_warp.h), kLanes at a time in
// generic vectors (core/vector_lanes.h): each lane does the scalar code's
// IEEE operations in its order (comparisons and selects for its branches and
// clamps; the build has -ffp-contract=off), so every instruction set gives
// the scalar code's bits. mesh_warp.cc builds them for the baseline (SSE2),
// mesh_warp_avx.cc for AVX, mesh_warp_avx2.cc for AVX2 (the kAvx2 path:
// 256-bit integer lanes and gathers) and mesh_warp_avx512.cc for AVX-512F;
// MeshWarp dispatches on math::BestVectorPath(). Internal linkage (an
// anonymous namespace) on purpose: each of the four files keeps its own
// copy, compiled for its instruction set, which the linker never merges (nm
// shows none of the wider builds' objects exporting a weak symbol the
// baseline could pick up).
//
// Thread-safety: pure functions.
#ifndef SFCSAMPLER_MESH_MESH_WARP_LANES_H_
#define SFCSAMPLER_MESH_MESH_WARP_LANES_H_

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "core/vector_lanes.h"
#include "core/vector_math.h"
#include "mesh/mesh_curve_tree.h"

namespace sfc::mesh_warp_lanes {

// Coordinates are clamped to [0, kBelowOne].
using math::kBelowOne;

// What the leaf search reads of a MeshWarp (mesh_warp.h's members).
struct LeafTables {
  const double* ends;             // MeshCurveTree::mass_ends()
  const uint32_t* bucket_leaves;  // MeshWarp::bucket_leaves_
  double total;                   // MeshCurveTree::total_mass()
  int max_depth, bucket_bits;
};

// Bit i of x at bit 2i, for x < 2^32 (a uint64_t or a vector of them).
template <typename T>
__attribute__((always_inline)) inline T Spread(T x) {
  x = (x | x << 16) & 0x0000ffff0000ffffULL;
  x = (x | x << 8) & 0x00ff00ff00ff00ffULL;
  x = (x | x << 4) & 0x0f0f0f0f0f0f0f0fULL;
  x = (x | x << 2) & 0x3333333333333333ULL;
  return (x | x << 1) & 0x5555555555555555ULL;
}

// The AVX-512F builds of the loops below (mesh_warp_avx512.cc).
void PathsOfAvx512(size_t n, const double* pa, const double* pb, uint64_t* paths);
void LeafSharesAvx512(const LeafTables& tables, size_t n, const double* a, const double* b,
                      int64_t* leaf, double* f, double* g, int64_t* across);
void PlaceUniformAvx512(size_t n, const double* f, const double* g, double* pa, double* pb);
// The AVX2 builds (mesh_warp_avx2.cc).
void PathsOfAvx2(size_t n, const double* pa, const double* pb, uint64_t* paths);
void LeafSharesAvx2(const LeafTables& tables, size_t n, const double* a, const double* b,
                    int64_t* leaf, double* f, double* g, int64_t* across);
void PlaceUniformAvx2(size_t n, const double* f, const double* g, double* pa, double* pb);
// The AVX builds (mesh_warp_avx.cc).
void PathsOfAvx(size_t n, const double* pa, const double* pb, uint64_t* paths);
void LeafSharesAvx(const LeafTables& tables, size_t n, const double* a, const double* b,
                   int64_t* leaf, double* f, double* g, int64_t* across);
void PlaceUniformAvx(size_t n, const double* f, const double* g, double* pa, double* pb);

namespace {

using vector_lanes::Any;
using vector_lanes::Doubles;
using vector_lanes::Gather;
using vector_lanes::Ints;
using vector_lanes::kLanes;
using vector_lanes::Words;

// MeshCurveTree::PathOf over kLanes x kVectors lanes at once. The vectors
// are independent chains of kLevels steps that the CPU overlaps.
constexpr int kVectors = 4, kBlock = kLanes * kVectors;

// One level of PathsOfBlock for each vector. kFirst: the scalar code's
// clamps in full. After a level (a, b) lies in the frame's triangle as the
// clamps leave it: a in [0, 1], b in [0, fl(1 - a)]. From there, in IEEE
// arithmetic (round to nearest, no FMA), two of the four clamps can never
// act, so the later levels skip them:
// - child (E, A, M), fl(2a + b) < 1: then 2a + b < 1 exactly, so the new a
//   = b is in [0, 1], and the new b = 2a (exact) < 1 - b, so 2a <= fl(1 -
//   b): its upper clamp holds too;
// - child (A, X, M): 2a + b <= 2 exactly (b <= fl(1 - a), which is 1 - a
//   for a >= 1/2 and at most 1 otherwise), so s = fl(2a + b) is in [1, 2]
//   and the new a = s - 1 (exact) in [0, 1]; the new b = 2 fl(fl(1 - a) -
//   b) >= 0. Only its upper clamp, fl(1 - new a), can act.
// The comparisons that choose the children see the same values either way,
// so the paths are the scalar code's (tests/mesh_warp_test.cc checks them).
template <bool kFirst>
__attribute__((always_inline)) inline void PathLevel(Doubles* a, Doubles* b, Words* p) {
  const Doubles zero{}, one = zero + 1.0;
  for (int v = 0; v < kVectors; ++v) {
    // Child (E, A, M): (a, b) -> (b, 2a); child (A, X, M): (a, b) ->
    // (2a + b - 1, 2 (1 - a - b)).
    const Doubles twice = 2 * a[v];
    const Doubles s = twice + b[v];
    const Ints first = s < one;
    const Doubles na = first ? b[v] : s - 1;
    const Doubles nb = first ? twice : 2 * (1 - a[v] - b[v]);
    if (kFirst) {
      // std::clamp(na, 0, 1), then std::clamp(nb, 0, 1 - a).
      a[v] = na < zero ? zero : (one < na ? one : na);
      const Doubles top = 1 - a[v];
      b[v] = nb < zero ? zero : (top < nb ? top : nb);
    } else {
      a[v] = na;
      const Doubles top = 1 - na;
      b[v] = top < nb ? top : nb;
    }
    p[v] = p[v] << 1;
    p[v] = first ? p[v] : p[v] | 1;
  }
}

__attribute__((always_inline)) inline void PathsOfBlock(const double* pa, const double* pb,
                                                        uint64_t* paths) {
  Doubles a[kVectors], b[kVectors];
  Words p[kVectors];
  for (int v = 0; v < kVectors; ++v) {
    std::memcpy(&a[v], pa + v * kLanes, sizeof(Doubles));
    std::memcpy(&b[v], pb + v * kLanes, sizeof(Doubles));
    p[v] = Words{};
  }
  PathLevel<true>(a, b, p);
  for (int level = 1; level < MeshCurveTree::kLevels; ++level) PathLevel<false>(a, b, p);
  for (int v = 0; v < kVectors; ++v) std::memcpy(paths + v * kLanes, &p[v], sizeof(Words));
}

// MeshWarp::PathsOf's batch: blocks, and the tail padded to a block.
__attribute__((always_inline)) inline void PathsOfLanes(size_t n, const double* pa,
                                                        const double* pb, uint64_t* paths) {
  size_t i = 0;
  for (; i + kBlock <= n; i += kBlock) PathsOfBlock(pa + i, pb + i, paths + i);
  if (i < n) {
    double a[kBlock] = {}, b[kBlock] = {};
    uint64_t p[kBlock];
    std::copy(pa + i, pa + n, a), std::copy(pb + i, pb + n, b);
    PathsOfBlock(a, b, p);
    std::copy(p, p + (n - i), paths + i);
  }
}

// x exactly, for 0 <= x < 2^52: x in the mantissa of 2^52, less 2^52.
__attribute__((always_inline)) inline Doubles ExactDouble(Ints x) {
  return (Doubles)(x | 0x4330000000000000LL) - 0x1.0p52;
}
// floor(x) as an integer, exactly, for 0 <= x < 2^51 (-0 included): x + 2^52
// rounds x to an integer in the mantissa, one less where that went up: plain
// vector operations on every build (conversions to 64-bit integers would need
// AVX-512DQ), and static_cast's truncation for these x.
__attribute__((always_inline)) inline Ints FloorOf(Doubles x) {
  const Doubles big = x + 0x1.0p52;
  const Ints up = big - 0x1.0p52 > x;
  return ((Ints)big - 0x4330000000000000LL) + up;  // up is -1 where true
}
// 2^k for |k| <= 1022 (the scalar Pow2's exponent field).
__attribute__((always_inline)) inline Doubles Pow2(Ints k) { return (Doubles)((k + 1023) << 52); }

// LeafShareBlock's vectors: independent chains of dependent gathers, which
// the CPU overlaps.
constexpr int kShareVectors = 4, kShareBlock = kLanes * kShareVectors;

// The first index i in [base, base + len) with e[i] > x (kAtOrAbove false)
// or e[i] >= x (true), base + len if none, in each lane of kShareVectors
// vectors: std::upper_bound's and std::lower_bound's answer (mesh_warp.cc's
// FirstAbove, FirstAtOrAbove), into base.
template <bool kAtOrAbove>
__attribute__((always_inline)) inline void FirstNotBefore(const double* e, Ints* base, Ints* len,
                                                          const Doubles* x) {
  const Ints none{};
  for (;;) {
    Ints half[kShareVectors], step[kShareVectors], any{};
    for (int v = 0; v < kShareVectors; ++v) {
      half[v] = len[v] >> 1, step[v] = half[v] > none;
      any |= step[v];
    }
    if (!Any(any)) break;
    for (int v = 0; v < kShareVectors; ++v) {
      const Doubles probe = Gather(e, step[v] ? base[v] + half[v] - 1 : base[v]);
      const Ints before = kAtOrAbove ? probe < x[v] : probe <= x[v];
      base[v] = (step[v] & before) ? base[v] + half[v] : base[v];
      len[v] -= half[v];
    }
  }
  for (int v = 0; v < kShareVectors; ++v) {
    const Doubles probe = Gather(e, base[v]);
    const Ints before = kAtOrAbove ? probe < x[v] : probe <= x[v];
    base[v] = ((len[v] > none) & before) ? base[v] + 1 : base[v];
  }
}

// MeshWarp::LeafShare for kShareBlock points (its comments give the steps):
// leaf[k], f[k], g[k] its results, bit for bit, where across[k] is 0; where
// it is not, the point's node still straddles leaves at the depth cap, and
// the scalar code places it.
__attribute__((always_inline)) inline void LeafShareBlock(const LeafTables& t, const double* a_in,
                                                          const double* b_in, int64_t* leaf_out,
                                                          double* f_out, double* g_out,
                                                          int64_t* across_out) {
  constexpr int V = kShareVectors;
  const Doubles zero{}, below = zero + kBelowOne, one = zero + 1.0;
  const Ints izero{};
  const int64_t max_depth = t.max_depth;
  const int64_t bits_a = (max_depth + 1) / 2, bits_b = max_depth / 2;
  const Doubles cap_scale = Pow2(izero - max_depth);
  Doubles c0[V], c1[V], x_lo[V], x_hi[V];
  Words cap_node[V];
  Ints from[V], lo[V], hi[V], len_lo[V], len_hi[V];
  for (int v = 0; v < V; ++v) {
    std::memcpy(&c0[v], a_in + v * kLanes, sizeof(Doubles));
    std::memcpy(&c1[v], b_in + v * kLanes, sizeof(Doubles));
    c0[v] = c0[v] < zero ? zero : (below < c0[v] ? below : c0[v]);
    c1[v] = c1[v] < zero ? zero : (below < c1[v] ? below : c1[v]);
    const Words top_a = Spread((Words)FloorOf(c0[v] * Pow2(izero + bits_a)));
    const Words top_b = Spread((Words)FloorOf(c1[v] * Pow2(izero + bits_b)));
    cap_node[v] = max_depth % 2 == 0 ? top_a << 1 | top_b : top_a | top_b << 1;
    const Ints bucket = (Ints)(cap_node[v] >> (max_depth - t.bucket_bits));
    from[v] = Gather(t.bucket_leaves, 2 * bucket);
    len_lo[v] = Gather(t.bucket_leaves, 2 * bucket + 1) + 1 - from[v];
    len_hi[v] = len_lo[v], lo[v] = from[v], hi[v] = from[v];
    x_lo[v] = ExactDouble((Ints)cap_node[v]) * cap_scale * t.total;
    x_hi[v] = ExactDouble((Ints)cap_node[v] + 1) * cap_scale * t.total;
  }
  FirstNotBefore<false>(t.ends, lo, len_lo, x_lo);
  FirstNotBefore<true>(t.ends, hi, len_hi, x_hi);
  // The bisection for the first depth whose node holds mass of leaf lo alone.
  Doubles lo_begin[V], lo_end[V];
  Ints across[V], depth[V], shallow[V];
  for (int v = 0; v < V; ++v) {
    across[v] = lo[v] != hi[v];
    lo[v] = across[v] ? from[v] : lo[v];  // the scalar code takes these lanes: any valid leaf
    lo_begin[v] = lo[v] == izero ? zero : Gather(t.ends, lo[v] == izero ? lo[v] : lo[v] - 1);
    lo_end[v] = Gather(t.ends, lo[v]);
    depth[v] = izero + max_depth, shallow[v] = across[v] ? depth[v] : izero;
  }
  for (;;) {
    Ints active[V], any{};
    for (int v = 0; v < V; ++v) active[v] = shallow[v] < depth[v], any |= active[v];
    if (!Any(any)) break;
    for (int v = 0; v < V; ++v) {
      const Ints mid = (shallow[v] + depth[v]) >> 1;
      const Ints node = (Ints)(cap_node[v] >> (Words)(max_depth - mid));
      const Doubles scale = Pow2(-mid);
      const Ints inside = (ExactDouble(node) * scale * t.total >= lo_begin[v]) &
                          (ExactDouble(node + 1) * scale * t.total <= lo_end[v]);
      depth[v] = (active[v] & inside) ? mid : depth[v];
      shallow[v] = (active[v] & ~inside) ? mid + 1 : shallow[v];
    }
  }
  for (int v = 0; v < V; ++v) {
    // What is left of each coordinate below the node's bits (+ 0 makes the
    // -0 of -0 - 0 the scalar's +0).
    const Doubles scaled_a = c0[v] * Pow2((depth[v] + 1) >> 1);
    const Doubles scaled_b = c1[v] * Pow2(depth[v] >> 1);
    const Doubles rest_a = (scaled_a - ExactDouble(FloorOf(scaled_a))) + 0.0;
    const Doubles rest_b = (scaled_b - ExactDouble(FloorOf(scaled_b))) + 0.0;
    const Ints axis = (depth[v] & 1) != izero;
    const Doubles w = Pow2(-depth[v]);
    const Doubles t0 = ExactDouble((Ints)(cap_node[v] >> (Words)(max_depth - depth[v]))) * w;
    const Doubles leaf_begin = lo_begin[v], leaf_mass = lo_end[v] - lo_begin[v];
    const Ints has_mass = leaf_mass > zero;
    const Doubles r0 = (t0 * t.total - leaf_begin) / leaf_mass;
    const Doubles r1 = ((t0 + w) * t.total - leaf_begin) / leaf_mass;
    const Doubles f0 = has_mass ? (r0 < zero ? zero : (one < r0 ? one : r0)) : zero;
    const Doubles f1 = has_mass ? (r1 < zero ? zero : (one < r1 ? one : r1)) : one;
    const Doubles along = axis ? rest_b : rest_a, across_leaf = axis ? rest_a : rest_b;
    const Doubles f = f0 + along * (f1 - f0);
    std::memcpy(leaf_out + v * kLanes, &lo[v], sizeof(Ints));
    std::memcpy(f_out + v * kLanes, &f, sizeof f);
    std::memcpy(g_out + v * kLanes, &across_leaf, sizeof across_leaf);
    std::memcpy(across_out + v * kLanes, &across[v], sizeof(Ints));
  }
}

// LeafShareBlock over n points, the tail padded with (0, 0).
__attribute__((always_inline)) inline void LeafSharesOf(const LeafTables& tables, size_t n,
                                                        const double* a, const double* b,
                                                        int64_t* leaf, double* f, double* g,
                                                        int64_t* across) {
  size_t i = 0;
  for (; i + kShareBlock <= n; i += kShareBlock) {
    LeafShareBlock(tables, a + i, b + i, leaf + i, f + i, g + i, across + i);
  }
  if (i < n) {
    double pa[kShareBlock] = {}, pb[kShareBlock] = {}, pf[kShareBlock], pg[kShareBlock];
    int64_t pl[kShareBlock], px[kShareBlock];
    std::copy(a + i, a + n, pa), std::copy(b + i, b + n, pb);
    LeafShareBlock(tables, pa, pb, pl, pf, pg, px);
    std::copy(pl, pl + (n - i), leaf + i), std::copy(pf, pf + (n - i), f + i);
    std::copy(pg, pg + (n - i), g + i), std::copy(px, px + (n - i), across + i);
  }
}

// The correctly rounded square root in each lane (one vsqrtpd where the
// build has -fno-math-errno and the vector width).
__attribute__((always_inline)) inline Doubles Sqrt(Doubles x) {
  for (int k = 0; k < kLanes; ++k) x[k] = std::sqrt(x[k]);
  return x;
}

// mesh_warp.cc's PlaceInCell for a uniform cell (split 0.5), kLanes points.
__attribute__((always_inline)) inline void PlaceUniformVector(const double* f_in,
                                                              const double* g_in, double* pa,
                                                              double* pb) {
  Doubles f, b;
  std::memcpy(&f, f_in, sizeof f);
  std::memcpy(&b, g_in, sizeof b);
  const Doubles zero{}, split = zero + 0.5;
  const Ints first = f < split;
  const Doubles s = Sqrt(first ? f / split : (1 - f) / (1 - split));
  const Doubles ox = first ? zero : zero + 1.0;
  const Doubles a_out = ox + s * ((1 - b) * (0.5 - ox) + b * (0.0 - ox)), b_out = s * b;
  std::memcpy(pa, &a_out, sizeof a_out);
  std::memcpy(pb, &b_out, sizeof b_out);
}

// PlaceUniformVector over n points, the tail padded with zeros.
__attribute__((always_inline)) inline void PlaceUniformOf(size_t n, const double* f,
                                                          const double* g, double* pa, double* pb) {
  size_t i = 0;
  for (; i + kLanes <= n; i += kLanes) PlaceUniformVector(f + i, g + i, pa + i, pb + i);
  if (i < n) {
    double pf[kLanes] = {}, pg[kLanes] = {}, qa[kLanes], qb[kLanes];
    std::copy(f + i, f + n, pf), std::copy(g + i, g + n, pg);
    PlaceUniformVector(pf, pg, qa, qb);
    std::copy(qa, qa + (n - i), pa + i), std::copy(qb, qb + (n - i), pb + i);
  }
}

}  // namespace
}  // namespace sfc::mesh_warp_lanes

#endif  // SFCSAMPLER_MESH_MESH_WARP_LANES_H_
