// The vector paths of TreeWarp (core/tree_warp.h): one source,
// core/tree_warp_lanes.h, built for AVX-512F in core/tree_warp_avx512.cc,
// which TreeWarp calls only on the kAvx512 vector path
// (math::BestVectorPath()), and for AVX2 in core/tree_warp_avx2.cc, called
// only on the kAvx2 path. Each gives the bits of the scalar code in
// core/tree_warp.cc (which the other paths run). Not for use outside
// TreeWarp.
#ifndef SFCSAMPLER_CORE_TREE_WARP_INTERNAL_H_
#define SFCSAMPLER_CORE_TREE_WARP_INTERNAL_H_

#include <cstddef>
#include <cstdint>

#include "core/vector_math.h"

namespace sfc::tree_warp_internal {

// A rescaled coordinate stays in [0, 1): clamped to math::kBelowOne.
using math::kBelowOne;

// The Newton steps an inverse CDF takes at most (then its value as it stands).
inline constexpr int kCdfMaxSteps = 100;

// TreeWarp::Descend<2> for the points i < m, eight lanes to a vector.
// Returns how many points it took (a multiple of eight, at most 64); the
// caller descends the rest.
size_t DescendGrid2Avx512(size_t m, double* a, double* b, int32_t* ref, uint8_t* state,
                          const double* splits, const int32_t* children, const int32_t* state_at);

// TreeWarp::DigitsInLeaf for a Hilbert tree, eight points to a vector.
// Returns how many points it took (a multiple of eight); the caller encodes
// the rest (none unless cells <= 2^30).
size_t DigitsGrid2Avx512(size_t m, const double* x, const double* y, const uint8_t* state,
                         double cells, uint64_t top, int chunks, int head, const int32_t* child_at,
                         const int32_t* state_at, const uint64_t* encode, uint64_t* digits);

// out[lanes[j]]: the inverse CDF of problem lanes[j] (density p, share), j <
// n <= 64, each lane the scalar inversion's steps.
void InvertCdfsAvx512(size_t n, const uint8_t* lanes, const double (*p)[3], const double* share,
                      double* out);

// The same three, four lanes to a vector on AVX2:
// DescendGrid2Avx2 returns a multiple of four (at most 64), DigitsGrid2Avx2
// a multiple of four (none unless cells <= 2^30).
size_t DescendGrid2Avx2(size_t m, double* a, double* b, int32_t* ref, uint8_t* state,
                        const double* splits, const int32_t* children, const int32_t* state_at);
size_t DigitsGrid2Avx2(size_t m, const double* x, const double* y, const uint8_t* state,
                       double cells, uint64_t top, int chunks, int head, const int32_t* child_at,
                       const int32_t* state_at, const uint64_t* encode, uint64_t* digits);
void InvertCdfsAvx2(size_t n, const uint8_t* lanes, const double (*p)[3], const double* share,
                    double* out);

}  // namespace sfc::tree_warp_internal

#endif  // SFCSAMPLER_CORE_TREE_WARP_INTERNAL_H_
