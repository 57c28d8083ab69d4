// The scrambles behind the radical-inverse sequences (core/sequence.h):
// progressive's nested Owen scramble (its table of flips) and sobol's random
// linear scramble with a digital shift (its tables), each for one value or
// for eight lanes (GCC's vector extensions), shared by
// core/sequence.cc and its AVX-512F path core/sequence_avx512.cc (built with
// -mavx512f; Sequence calls it only on the kAvx512 vector path). Integer
// operations and one exact conversion, so every lane has the scalar code's
// bits. Not for use outside Sequence.
#ifndef SFCSAMPLER_CORE_SEQUENCE_INTERNAL_H_
#define SFCSAMPLER_CORE_SEQUENCE_INTERNAL_H_

#include <cstddef>
#include <cstdint>
#include <type_traits>

#include "base/counter_hash.h"

namespace sfc {

namespace sequence_internal {

// Levels whose flips a scramble keeps in a table (2^12 - 1 bits a coordinate).
inline constexpr int kTableLevels = 12;
// Below the table, one hash of a node at level 12 + 4 j gives the flips of
// the 15 nodes of the 4 levels from it (a node at depth d under it, with
// path p, takes bit 2^d - 1 + p): every node of the scramble's tree still gets
// a bit of its own.
inline constexpr int kBlockLevels = 4;

}  // namespace sequence_internal

// A sequence's scrambles, one a coordinate, computed once per sequence.
// progressive (nested, coordinate 0): top[0][t] holds the flips of the levels
// i < kTableLevels (bit 31 - i for level i, as NestedScramble xors them) of
// the coordinate whose top kTableLevels bits are t: one look-up for the
// table's levels. sobol (linear, coordinates 0 and 1): linear[dim][b][x] is
// the scrambled generator matrix times byte b of k being x, and shift[dim]
// the digital shift (LinearScramble).
struct ScrambleTables {
  uint64_t key[2];       // the keys of the flips below the table (BlockHash)
  uint64_t tail_key[2];  // the keys of the bits below 2^-32
  uint32_t top[1][1 << sequence_internal::kTableLevels];
  uint32_t linear[2][4][256];
  uint32_t shift[2];
};

namespace sequence_internal {

// Eight lanes of uint64_t or double: one register on AVX-512F.
typedef uint64_t U64x8 __attribute__((vector_size(64)));
typedef double F64x8 __attribute__((vector_size(64)));

// Always inlined, here and below, so that no out-of-line copy built for
// AVX-512F can stand in for the scalar one at link time.
__attribute__((always_inline)) inline uint32_t ReverseBits32(uint32_t x) {
  x = ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
  x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
  x = ((x >> 4) & 0x0f0f0f0fu) | ((x & 0x0f0f0f0fu) << 4);
  x = ((x >> 8) & 0x00ff00ffu) | ((x & 0x00ff00ffu) << 8);
  return (x >> 16) | (x << 16);
}

// The hash of the node at level i whose i bits above are `prefix`: one
// SplitMix64 finaliser (Steele, Lea and Flood 2014), keyed by the scramble.
template <typename U>
__attribute__((always_inline)) inline U BlockHash(uint64_t key, U prefix, int i) {
  return Mix64(key + 0x9e3779b97f4a7c15ULL * ((prefix << 6) | static_cast<uint64_t>(i)));
}

// The table's flips for the top levels of r (< 2^32), and the conversion of
// a value below 2^53 to double (exact), for one value or for eight lanes.
template <typename U>
__attribute__((always_inline)) inline U TopFlips(const ScrambleTables& table, int dim, U r) {
  if constexpr (std::is_integral_v<U>) {
    return table.top[dim][r >> (32 - kTableLevels)];
  } else {
    U flips;
    for (int j = 0; j < 8; ++j) flips[j] = table.top[dim][r[j] >> (32 - kTableLevels)];
    return flips;
  }
}
template <typename U>
__attribute__((always_inline)) inline auto ToDouble(U x) {
  if constexpr (std::is_integral_v<U>) {
    return static_cast<double>(x);
  } else {
    return __builtin_convertvector(x, F64x8);
  }
}

// The scrambled digits r (< 2^32) of sample k of coordinate dim as a double
// in [0, 1): the bits below 2^-32 are uniform random bits of (tail key, k)
// (UniformOf(KeyedHash(tail_key[dim], CounterMix(k))), base/counter_hash.h:
// k's CounterMix is shared by the coordinates).
template <typename U>
__attribute__((always_inline)) inline auto ToUnit(U r, U k_mix, int dim,
                                                  const ScrambleTables& table) {
  const auto tail = ToDouble(KeyedHash(table.tail_key[dim], k_mix) >> 11) * 0x1.0p-53;
  return (ToDouble(r) + tail) * 0x1.0p-32;
}

// Owen's nested uniform scramble (Owen 1995) of the 32 digits `r` of sample
// k, as a double in [0, 1): bit i (from the top) is flipped by a random bit
// of its node in the binary tree of prefixes (the i bits of r above it), so
// every aligned block of 2^m values is stratified in 2^-m. The top levels'
// bits come from the sequence's table, the others a block of levels per
// hash. The bits below 2^-32 are uniform random bits, as a full scramble of
// the all-zero tail would make them (ToUnit). U: uint64_t holding r
// (< 2^32), or eight lanes of them.
template <typename U>
__attribute__((always_inline)) inline auto NestedScramble(U r, U k_mix, int dim,
                                                          const ScrambleTables& table) {
  // The flips of all 32 levels as one mask, then one xor.
  U flips = TopFlips(table, dim, r);
  for (int root = kTableLevels; root < 32; root += kBlockLevels) {
    const U block = BlockHash(table.key[dim], r >> (32 - root), root);
    for (int depth = 0; depth < kBlockLevels; ++depth) {
      const int i = root + depth;
      const U path = (r >> (32 - i)) & ((uint64_t{1} << depth) - 1);
      flips |= ((block >> (((uint64_t{1} << depth) - 1) + path)) & 1) << (31 - i);
    }
  }
  return ToUnit(r ^ flips, k_mix, dim, table);
}

// Sobol's coordinate dim of sample k (< 2^32) under Matousek's random linear
// scramble with a digital shift (Matousek 1998): the digits are the generator
// matrix times k's bits, times a random lower-triangular binary matrix with
// unit diagonal (digit i plus a random combination of the digits above it),
// plus a random digit vector. The matrices are nonsingular and keep every
// digit's dependence on the digits above, so every aligned block of 2^m
// points stays a (0,m,2)-net. The same variance as the nested scramble for
// nets (Owen 2003, "Variance with alternative scramblings of digital nets"),
// but most seeds' errors are far smaller, with rare large ones
// (docs/QUALITY.md, "Integration"). Linear in k's bits, so four look-ups of
// the sequence's byte tables and the shift. U: uint64_t holding k, or eight
// lanes of them.
template <typename U>
__attribute__((always_inline)) inline auto LinearScramble(U k, U k_mix, int dim,
                                                          const ScrambleTables& table) {
  const auto& t = table.linear[dim];
  U r;
  if constexpr (std::is_integral_v<U>) {
    r = t[0][k & 255] ^ t[1][k >> 8 & 255] ^ t[2][k >> 16 & 255] ^ t[3][k >> 24 & 255];
  } else {
    for (int j = 0; j < 8; ++j) {
      r[j] = t[0][k[j] & 255] ^ t[1][k[j] >> 8 & 255] ^ t[2][k[j] >> 16 & 255] ^
             t[3][k[j] >> 24 & 255];
    }
  }
  return ToUnit(r ^ table.shift[dim], k_mix, dim, table);
}

// Sobol points k0 + i (or ks[i]), i < n, eight lanes at a time on AVX-512F
// (core/sequence_avx512.cc): a[i] and b[i] as Sequence::PointsMany gives
// them. Returns how many it took (a multiple of eight); the caller computes
// the rest.
size_t PointsOnAvx512(const uint32_t* ks, uint64_t k0, size_t n, const ScrambleTables& table,
                      double* a, double* b);

}  // namespace sequence_internal
}  // namespace sfc

#endif  // SFCSAMPLER_CORE_SEQUENCE_INTERNAL_H_
