#include "core/sequence.h"

#include <algorithm>
#include <cassert>
#include <cstring>
#include <iterator>
#include <memory>

#include "base/counter_hash.h"

namespace sfc {
namespace {

uint32_t ReverseBits32(uint32_t x) {
  x = ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
  x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
  x = ((x >> 4) & 0x0f0f0f0fu) | ((x & 0x0f0f0f0fu) << 4);
  x = ((x >> 8) & 0x00ff00ffu) | ((x & 0x00ff00ffu) << 8);
  return (x >> 16) | (x << 16);
}

// Owen's nested uniform scrambling of the 32-bit radical inverse of k: bit i
// (from the top) is flipped by a random bit that depends on the bits above it,
// which permutes every dyadic level and so keeps each 2^m-prefix stratified.
// The bits below 2^-32 are filled with uniform random bits, as a full scramble
// of the all-zero tail would.
double OwenScrambledRadicalInverse(uint64_t k, uint64_t seed) {
  const uint32_t r = ReverseBits32(static_cast<uint32_t>(k));
  uint32_t out = 0;
  for (int i = 0; i < 32; ++i) {
    const uint32_t prefix = i == 0 ? 0 : r >> (32 - i);
    const uint32_t flip = CounterHash(seed, hash_stream::kOwen, (uint64_t{prefix} << 6) | i) & 1;
    out |= (((r >> (31 - i)) & 1) ^ flip) << (31 - i);
  }
  const double tail = CounterUniform(seed, hash_stream::kOwenTail, k);
  return (out + tail) * 0x1.0p-32;
}

// Sobol's second dimension (primitive polynomial x + 1, all m_i = 1): its
// generator matrix is Pascal's triangle mod 2, v_0 = 2^31 and v_i = v_{i-1} xor
// (v_{i-1} >> 1). With the base-2 radical inverse as the first dimension it
// is a (0,2)-sequence: every 2^m-prefix is a (0,m,2)-net (Sobol 1967; Niederreiter
// 1992, Sect. 4.5).
// It is linear in k's bits (an xor of v_i over the bits set), so four tables
// of 256 entries, one a byte of k, give it in four look-ups.
struct SobolSecondTables {
  uint32_t byte[4][256];
  SobolSecondTables() {
    uint32_t v[32];
    v[0] = 0x80000000u;
    for (int i = 1; i < 32; ++i) v[i] = v[i - 1] ^ (v[i - 1] >> 1);
    for (int b = 0; b < 4; ++b) {
      for (uint32_t x = 0; x < 256; ++x) {
        uint32_t out = 0;
        for (int i = 0; i < 8; ++i) {
          if (x >> i & 1) out ^= v[8 * b + i];
        }
        byte[b][x] = out;
      }
    }
  }
};
uint32_t SobolSecond(uint32_t k) {
  static const SobolSecondTables tables;
  return tables.byte[0][k & 255] ^ tables.byte[1][k >> 8 & 255] ^ tables.byte[2][k >> 16 & 255] ^
         tables.byte[3][k >> 24];
}

// The flip of bit i (from the top) of the sobol coordinate `dim`, whose i
// bits above it are `prefix`: a random bit of (seed, dimension, i, prefix).
// One SplitMix64 finaliser (Steele, Lea and Flood 2014), keyed by the seed and
// the dimension.
uint64_t SobolKey(uint64_t seed, int dim) { return CounterKey(seed, hash_stream::kSobol[dim]); }
template <typename U>
U BlockHash(uint64_t key, U prefix, int i) {
  return Mix64(key + 0x9e3779b97f4a7c15ULL * ((prefix << 6) | static_cast<uint64_t>(i)));
}
uint32_t SobolFlip(uint64_t key, uint64_t prefix, int i) {
  return static_cast<uint32_t>(BlockHash(key, prefix, i) >> 63);
}

// Levels whose flips a sequence keeps in a table (2^12 - 1 bits a coordinate).
constexpr int kTableLevels = 12;
// Below the table, one hash of a node at level 12 + 4 j gives the flips of
// the 15 nodes of the 4 levels from it (a node at depth d under it, with
// path p, takes bit 2^d - 1 + p): every node of the scramble's tree still gets
// a bit of its own.
constexpr int kBlockLevels = 4;

}  // namespace

// top[dim][t] holds the flips of the levels i < kTableLevels (bit 31 - i for
// level i, as NestedScramble xors them) of the coordinate whose top
// kTableLevels bits are t: one look-up for the table's levels.
struct OwenFlips {
  uint64_t key[2];
  uint64_t tail_key[2];  // CounterKey(seed, kSobolTail[dim])
  uint32_t top[2][1 << kTableLevels];
};

std::shared_ptr<const OwenFlips> Sequence::MakeOwenFlips(uint64_t seed) {
  auto t = std::make_shared<OwenFlips>();
  for (int dim = 0; dim < 2; ++dim) {
    t->key[dim] = SobolKey(seed, dim);
    t->tail_key[dim] = CounterKey(seed, hash_stream::kSobolTail[dim]);
    // Bit (2^i - 1 + prefix) of `flips` is the flip of level i, prefix its
    // i bits above it.
    uint64_t flips[(1 << kTableLevels) / 64] = {};
    for (int i = 0; i < kTableLevels; ++i) {
      for (uint64_t prefix = 0; prefix < (uint64_t{1} << i); ++prefix) {
        const uint64_t bit = (uint64_t{1} << i) - 1 + prefix;
        flips[bit / 64] |= uint64_t{SobolFlip(t->key[dim], prefix, i)} << (bit % 64);
      }
    }
    for (uint32_t top = 0; top < (1u << kTableLevels); ++top) {
      const uint32_t r = top << (32 - kTableLevels);
      uint32_t mask = 0;
      for (int i = 0; i < kTableLevels; ++i) {
        const uint64_t prefix = i == 0 ? 0 : r >> (32 - i);
        const uint64_t bit = (uint64_t{1} << i) - 1 + prefix;
        mask |= static_cast<uint32_t>((flips[bit / 64] >> (bit % 64)) & 1) << (31 - i);
      }
      t->top[dim][top] = mask;
    }
  }
  return t;
}

namespace {

// Eight lanes of uint64_t or double (GCC's vector extensions): one register
// on AVX-512F. Integer operations and one exact conversion, so every lane
// has the scalar code's bits.
typedef uint64_t U64x8 __attribute__((vector_size(64)));
typedef double F64x8 __attribute__((vector_size(64)));

// The table's flips for the top levels of r (< 2^32), and the conversion of
// a value below 2^53 to double (exact), for one value or for eight lanes.
uint64_t TopFlips(const OwenFlips& table, int dim, uint64_t r) {
  return table.top[dim][r >> (32 - kTableLevels)];
}
__attribute__((always_inline)) inline U64x8 TopFlips(const OwenFlips& table, int dim, U64x8 r) {
  U64x8 flips;
  for (int j = 0; j < 8; ++j) flips[j] = table.top[dim][r[j] >> (32 - kTableLevels)];
  return flips;
}
double ToDouble(uint64_t x) { return static_cast<double>(x); }
__attribute__((always_inline)) inline F64x8 ToDouble(U64x8 x) {
  return __builtin_convertvector(x, F64x8);
}

// Owen's nested uniform scramble (Owen 1995) of the 32 digits `r` of sample
// k, as a double in [0, 1): bit i (from the top) is flipped by a random bit
// of its node in the binary tree of prefixes (the i bits of r above it), so
// every 2^m-prefix of the sequence stays a (0,m,2)-net. The top levels' bits
// come from the sequence's table, the others a block of levels per hash. The
// bits below 2^-32 are uniform random bits of (seed, k), as a full scramble of
// the all-zero tail would make them (CounterUniform(seed, kSobolTail[dim], k),
// from k's CounterMix, which both coordinates share). U: uint64_t holding r
// (< 2^32), or eight lanes of them.
template <typename U>
__attribute__((always_inline)) inline auto NestedScramble(U r, U k_mix, int dim,
                                                          const OwenFlips& table) {
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
  // UniformOf (base/counter_hash.h) of the tail's hash.
  const auto tail = ToDouble(KeyedHash(table.tail_key[dim], k_mix) >> 11) * 0x1.0p-53;
  return (ToDouble(r ^ flips) + tail) * 0x1.0p-32;
}

// Sobol points k0 + i (or ks[i]), i < n, in eight lanes at a time, on
// AVX-512F; the rest one at a time.
__attribute__((target("avx512f"))) size_t PointsOnAvx512(const uint32_t* ks, uint64_t k0,
                                                        size_t n, const OwenFlips& table,
                                                        double* a, double* b) {
  size_t i = 0;
  for (; i + 8 <= n; i += 8) {
    U64x8 k, ra, rb;
    for (int j = 0; j < 8; ++j) {
      k[j] = ks != nullptr ? ks[i + j] : k0 + i + j;
      ra[j] = ReverseBits32(static_cast<uint32_t>(k[j]));
      rb[j] = SobolSecond(static_cast<uint32_t>(k[j]));
    }
    const U64x8 k_mix = CounterMix(k);
    const F64x8 va = NestedScramble(ra, k_mix, 0, table);
    const F64x8 vb = NestedScramble(rb, k_mix, 1, table);
    std::memcpy(a + i, &va, sizeof(va));
    std::memcpy(b + i, &vb, sizeof(vb));
  }
  return i;
}

}  // namespace

double Sequence::Raw(uint64_t k) const {
  switch (kind_) {
    case SequenceKind::kJittered:
      return (static_cast<double>(k) + CounterUniform(seed_, hash_stream::kJitter, k)) /
             static_cast<double>(count_);
    case SequenceKind::kEqual:
      return (static_cast<double>(k) + 0.5) / static_cast<double>(count_);
    case SequenceKind::kRandom:
      return CounterUniform(seed_, hash_stream::kRandom, k);
    case SequenceKind::kVanDerCorput:
      return ReverseBits32(static_cast<uint32_t>(k)) * 0x1.0p-32;
    case SequenceKind::kProgressive:
      return OwenScrambledRadicalInverse(k, seed_);
    case SequenceKind::kBlue:
      assert(table_ != nullptr && "a blue sequence is made by Sequence::FromTable");
      return (*table_)[k];
    case SequenceKind::kSobol:
      return NestedScramble<uint64_t>(ReverseBits32(static_cast<uint32_t>(k)), CounterMix(k), 0,
                                      *flips_);
  }
  return 0;
}

double Sequence::Second(uint64_t k) const {
  return NestedScramble<uint64_t>(SobolSecond(static_cast<uint32_t>(k)), CounterMix(k), 1,
                                  *flips_);
}

void Sequence::PointsMany(const uint32_t* ks, uint64_t k0, size_t n, double* a, double* b,
                          math::VectorPath path) const {
  assert(kind_ == SequenceKind::kSobol);
  // Eight lanes where 64-bit lanes are cheap; the scalar code elsewhere.
  const size_t done =
      path == math::VectorPath::kAvx512 ? PointsOnAvx512(ks, k0, n, *flips_, a, b) : 0;
  for (size_t i = done; i < n; ++i) {
    const uint64_t k = ks != nullptr ? ks[i] : k0 + i;
    const uint64_t k_mix = CounterMix(k);
    a[i] = NestedScramble<uint64_t>(ReverseBits32(static_cast<uint32_t>(k)), k_mix, 0, *flips_);
    b[i] = NestedScramble<uint64_t>(SobolSecond(static_cast<uint32_t>(k)), k_mix, 1, *flips_);
  }
  if (windowed_) {
    for (size_t i = 0; i < n; ++i) a[i] = (a[i] - lo_) / (hi_ - lo_);
  }
}

void Sequence::AtMany(uint64_t k0, size_t n, double* out) const {
  const double count = static_cast<double>(count_);
  switch (kind_) {
    case SequenceKind::kJittered:
      for (size_t i = 0; i < n; ++i) {
        const uint64_t k = k0 + i;
        out[i] = (static_cast<double>(k) + CounterUniform(seed_, hash_stream::kJitter, k)) / count;
      }
      break;
    case SequenceKind::kEqual:
      for (size_t i = 0; i < n; ++i) out[i] = (static_cast<double>(k0 + i) + 0.5) / count;
      break;
    case SequenceKind::kBlue:
      assert(table_ != nullptr && "a blue sequence is made by Sequence::FromTable");
      std::memcpy(out, table_->data() + k0, n * sizeof(double));
      break;
    default:
      for (size_t i = 0; i < n; ++i) out[i] = Raw(k0 + i);
      break;
  }
  if (windowed_) {
    for (size_t i = 0; i < n; ++i) out[i] = (out[i] - lo_) / (hi_ - lo_);
  }
}

}  // namespace sfc
