// Bit-parallel Hilbert decoding over a batch (Curve::DescendMany), written
// branch-free on 64-bit words so that a compiler vectorises it across the
// batch: integer work only, so every vector width gives the scalar bits.
// Included by curve.cc (baseline), curve_avx2.cc and curve_avx512.cc (built
// for those instruction sets, run only on CPUs that have them).
#ifndef SFCSAMPLER_CORE_HILBERT_BATCH_H_
#define SFCSAMPLER_CORE_HILBERT_BATCH_H_

#include <cstddef>
#include <cstdint>

namespace sfc::hilbert_batch {

// The curve's constants: per digit of orientation 0, all-ones or zero masks
// of its cell's x and y and of its child's swap and mirror-both; and the
// composition of an orientation s with the four a string can have as a whole
// (identity, swap, mirror both, both: 0, 1, 6, 7), 4 bits each at bit
// 4 (4 (s & 3) + w) of compose[s >> 2], for w = swap parity + 2 mirror parity.
// (A table in two words: a look-up by lane would stop the vectoriser.)
struct Masks {
  uint64_t x[4], y[4], swap[4], mirror[4];
  uint64_t compose[2];
};

// Bit j of the result: the XOR of the bits of `word` at j and above.
inline uint64_t SuffixXor(uint64_t word) {
  word ^= word >> 1;
  word ^= word >> 2;
  word ^= word >> 4;
  word ^= word >> 8;
  word ^= word >> 16;
  return word ^ word >> 32;
}
inline uint64_t EvenBits(uint64_t word) {
  word &= 0x5555555555555555ULL;
  word = (word | word >> 1) & 0x3333333333333333ULL;
  word = (word | word >> 2) & 0x0f0f0f0f0f0f0f0fULL;
  word = (word | word >> 4) & 0x00ff00ff00ff00ffULL;
  word = (word | word >> 8) & 0x0000ffff0000ffffULL;
  return (word | word >> 16) & 0x00000000ffffffffULL;
}

// Curve::Descend for n Hilbert strings of `levels` (<= 32) levels. The
// orientations of orientation 0's children form the abelian group
// {identity, swap, mirror both, swap and mirror both}, so the frame at each
// level is a swap and a mirror whose parities are XORs of per-digit flags
// over the levels above; the start orientation is applied to the whole
// result (every orientation acts on all bit levels alike).
inline void Descend(const Masks& m, const uint64_t* digits, int levels, size_t n, uint64_t* states,
                    uint64_t* xs, uint64_t* ys) {
  const uint64_t used = (uint64_t{1} << levels) - 1;
  for (size_t i = 0; i < n; ++i) {
    const uint64_t lo = EvenBits(digits[i]), hi = EvenBits(digits[i] >> 1);
    const uint64_t m0 = ~hi & ~lo & used, m1 = ~hi & lo & used, m2 = hi & ~lo & used,
                   m3 = hi & lo & used;
    const uint64_t qx = (m0 & m.x[0]) | (m1 & m.x[1]) | (m2 & m.x[2]) | (m3 & m.x[3]);
    const uint64_t qy = (m0 & m.y[0]) | (m1 & m.y[1]) | (m2 & m.y[2]) | (m3 & m.y[3]);
    const uint64_t swap = (m0 & m.swap[0]) | (m1 & m.swap[1]) | (m2 & m.swap[2]) | (m3 & m.swap[3]);
    const uint64_t mirror =
        (m0 & m.mirror[0]) | (m1 & m.mirror[1]) | (m2 & m.mirror[2]) | (m3 & m.mirror[3]);
    const uint64_t swap_suffix = SuffixXor(swap), mirror_suffix = SuffixXor(mirror);
    const uint64_t swap_above = swap_suffix >> 1, mirror_above = mirror_suffix >> 1;
    uint64_t px = ((qx & ~swap_above) | (qy & swap_above)) ^ (mirror_above & used);
    uint64_t py = ((qy & ~swap_above) | (qx & swap_above)) ^ (mirror_above & used);
    const uint64_t s = states[i];
    const uint64_t flip = 0 - (s & 1), mx = 0 - ((s >> 1) & 1), my = 0 - ((s >> 2) & 1);
    const uint64_t sx = (px & ~flip) | (py & flip), sy = (py & ~flip) | (px & flip);
    xs[i] = sx ^ (used & mx);
    ys[i] = sy ^ (used & my);
    // The whole string's orientation: swap parity (bit 0 of the suffix XOR) and mirror parity.
    const uint64_t w = (swap_suffix & 1) | ((mirror_suffix & 1) << 1);
    const uint64_t high = 0 - ((s >> 2) & 1);
    const uint64_t table = (m.compose[0] & ~high) | (m.compose[1] & high);
    states[i] = (table >> (4 * (4 * (s & 3) + w))) & 15;
  }
}

// The same, built for AVX2 (curve_avx2.cc) and AVX-512F (curve_avx512.cc).
void DescendAvx2(const Masks& m, const uint64_t* digits, int levels, size_t n, uint64_t* states,
                 uint64_t* xs, uint64_t* ys);
void DescendAvx512(const Masks& m, const uint64_t* digits, int levels, size_t n, uint64_t* states,
                   uint64_t* xs, uint64_t* ys);

}  // namespace sfc::hilbert_batch

#endif  // SFCSAMPLER_CORE_HILBERT_BATCH_H_
