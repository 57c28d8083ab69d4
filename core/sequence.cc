#include "core/sequence.h"

#include <algorithm>
#include <cassert>
#include <cstring>
#include <iterator>
#include <memory>

#include "base/counter_hash.h"
#include "core/sequence_internal.h"

namespace sfc {

using sequence_internal::kTableLevels;
using sequence_internal::LinearScramble;
using sequence_internal::NestedScramble;
using sequence_internal::ReverseBits32;

namespace {

// The flip of bit i (from the top) of the coordinate with scramble key `key`
// whose i bits above it are `prefix`.
uint32_t OwenFlip(uint64_t key, uint64_t prefix, int i) {
  return static_cast<uint32_t>(sequence_internal::BlockHash(key, prefix, i) >> 63);
}

// Column j of Sobol's generator matrix of coordinate dim, digit i at bit
// 31 - i. The first coordinate is the base-2 radical inverse (the identity).
// The second (primitive polynomial x + 1, all m_i = 1) is Pascal's triangle
// mod 2: v_0 = 2^31 and v_j = v_{j-1} xor (v_{j-1} >> 1). Together they are a
// (0,2)-sequence: every 2^m-prefix is a (0,m,2)-net (Sobol 1967; Niederreiter
// 1992, Sect. 4.5).
void SobolColumns(int dim, uint32_t v[32]) {
  v[0] = 0x80000000u;
  for (int j = 1; j < 32; ++j) v[j] = dim == 0 ? v[j - 1] >> 1 : v[j - 1] ^ (v[j - 1] >> 1);
}

// Fills sobol's linear scrambles (LinearScramble): row i of coordinate dim's
// lower-triangular matrix is digit i plus the digits j < i where bit 31 - j of
// the counter hash (seed, kSobol[dim], i) is set; the shift is that hash at
// counter 32.
void MakeLinearScrambles(uint64_t seed, ScrambleTables* t) {
  for (int dim = 0; dim < 2; ++dim) {
    uint32_t row[32];
    for (int i = 0; i < 32; ++i) {
      const uint32_t above = i == 0 ? 0 : ~uint32_t{0} << (32 - i);
      row[i] =
          (static_cast<uint32_t>(CounterHash(seed, hash_stream::kSobol[dim], i) >> 32) & above) |
          uint32_t{1} << (31 - i);
    }
    t->shift[dim] = static_cast<uint32_t>(CounterHash(seed, hash_stream::kSobol[dim], 32) >> 32);
    uint32_t v[32], w[32];
    SobolColumns(dim, v);
    for (int j = 0; j < 32; ++j) {
      w[j] = 0;
      for (int i = 0; i < 32; ++i) {
        w[j] |= static_cast<uint32_t>(__builtin_parity(row[i] & v[j])) << (31 - i);
      }
    }
    for (int b = 0; b < 4; ++b) {
      for (uint32_t x = 0; x < 256; ++x) {
        uint32_t out = 0;
        for (int j = 0; j < 8; ++j) {
          if (x >> j & 1) out ^= w[8 * b + j];
        }
        t->linear[dim][b][x] = out;
      }
    }
    t->tail_key[dim] = CounterKey(seed, hash_stream::kSobolTail[dim]);
  }
}

}  // namespace

std::shared_ptr<const ScrambleTables> Sequence::MakeScrambles(SequenceKind kind, uint64_t seed) {
  auto t = std::make_shared<ScrambleTables>();
  if (kind == SequenceKind::kSobol) {
    MakeLinearScrambles(seed, t.get());
    return t;
  }
  // progressive: one coordinate, nested.
  t->key[0] = CounterKey(seed, hash_stream::kOwen);
  t->tail_key[0] = CounterKey(seed, hash_stream::kOwenTail);
  // Bit (2^i - 1 + prefix) of `flips` is the flip of level i, prefix its
  // i bits above it.
  uint64_t flips[(1 << kTableLevels) / 64] = {};
  for (int i = 0; i < kTableLevels; ++i) {
    for (uint64_t prefix = 0; prefix < (uint64_t{1} << i); ++prefix) {
      const uint64_t bit = (uint64_t{1} << i) - 1 + prefix;
      flips[bit / 64] |= uint64_t{OwenFlip(t->key[0], prefix, i)} << (bit % 64);
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
    t->top[0][top] = mask;
  }
  return t;
}

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
    case SequenceKind::kBlue:
      assert(table_ != nullptr && "a blue sequence is made by Sequence::FromTable");
      return (*table_)[k];
    case SequenceKind::kProgressive:
      return NestedScramble<uint64_t>(ReverseBits32(static_cast<uint32_t>(k)), CounterMix(k), 0,
                                      *scrambles_);
    case SequenceKind::kSobol:
      return LinearScramble<uint64_t>(k, CounterMix(k), 0, *scrambles_);
  }
  return 0;
}

double Sequence::Second(uint64_t k) const {
  return LinearScramble<uint64_t>(k, CounterMix(k), 1, *scrambles_);
}

void Sequence::PointsMany(const uint32_t* ks, uint64_t k0, size_t n, double* a, double* b,
                          math::VectorPath path) const {
  assert(kind_ == SequenceKind::kSobol);
  // Eight lanes where 64-bit lanes are cheap; the scalar code elsewhere.
  const size_t done = path == math::VectorPath::kAvx512
                          ? sequence_internal::PointsOnAvx512(ks, k0, n, *scrambles_, a, b)
                          : 0;
  for (size_t i = done; i < n; ++i) {
    const uint64_t k = ks != nullptr ? ks[i] : k0 + i;
    const uint64_t k_mix = CounterMix(k);
    a[i] = LinearScramble<uint64_t>(k, k_mix, 0, *scrambles_);
    b[i] = LinearScramble<uint64_t>(k, k_mix, 1, *scrambles_);
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
