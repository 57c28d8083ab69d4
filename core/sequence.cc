#include "core/sequence.h"

#include <cassert>
#include <cstring>

#include "base/counter_hash.h"

namespace sfc {
namespace {

// Streams of the counter hash, one per use, so no two uses share bits.
constexpr uint64_t kJitterStream = 1;
constexpr uint64_t kRandomStream = 2;
constexpr uint64_t kOwenStream = 3;
constexpr uint64_t kOwenTailStream = 4;

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
    const uint32_t flip = CounterHash(seed, kOwenStream, (uint64_t{prefix} << 6) | i) & 1;
    out |= (((r >> (31 - i)) & 1) ^ flip) << (31 - i);
  }
  const double tail = CounterUniform(seed, kOwenTailStream, k);
  return (out + tail) * 0x1.0p-32;
}

}  // namespace

double Sequence::Raw(uint64_t k) const {
  switch (kind_) {
    case SequenceKind::kJittered:
      return (static_cast<double>(k) + CounterUniform(seed_, kJitterStream, k)) /
             static_cast<double>(count_);
    case SequenceKind::kEqual:
      return (static_cast<double>(k) + 0.5) / static_cast<double>(count_);
    case SequenceKind::kRandom:
      return CounterUniform(seed_, kRandomStream, k);
    case SequenceKind::kVanDerCorput:
      return ReverseBits32(static_cast<uint32_t>(k)) * 0x1.0p-32;
    case SequenceKind::kProgressive:
      return OwenScrambledRadicalInverse(k, seed_);
    case SequenceKind::kBlue:
      assert(table_ != nullptr && "a blue sequence is made by Sequence::FromTable");
      return (*table_)[k];
  }
  return 0;
}

void Sequence::AtMany(uint64_t k0, size_t n, double* out) const {
  const double count = static_cast<double>(count_);
  switch (kind_) {
    case SequenceKind::kJittered:
      for (size_t i = 0; i < n; ++i) {
        const uint64_t k = k0 + i;
        out[i] = (static_cast<double>(k) + CounterUniform(seed_, kJitterStream, k)) / count;
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
