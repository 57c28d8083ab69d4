// The 3D Hilbert curve index of a point of a 2^21 x 2^21 x 2^21 grid, by
// J. Skilling, "Programming the Hilbert curve", AIP Conf. Proc. 707 (2004):
// the axes are turned into the "transposed" Hilbert index by undoing the
// excess work, Gray-encoded, and the bits interleaved into one 63-bit key.
// Consecutive keys are face-adjacent cells (the tests check it). It orders
// the pieces of a surface made of pieces along one curve: a mesh's triangles
// (mesh/mesh_curve_tree.h) and a CAD model's faces (cad/face_order.h).
//
// Thread-safety: pure functions.
#ifndef SFCSAMPLER_CORE_HILBERT3D_H_
#define SFCSAMPLER_CORE_HILBERT3D_H_

#include <cstddef>
#include <cstdint>

namespace sfc {

// A bijection of the cells onto [0, 2^(3 bits)). REQUIRES: 1 <= bits <= 21 and
// x, y, z < 2^bits.
namespace hilbert3d_internal {

// Spreads the low 21 bits of v to every third bit (bit i to bit 3 i).
inline uint64_t Spread3(uint32_t v) {
  uint64_t x = v & 0x1fffffu;
  x = (x | x << 32) & 0x1f00000000ffffull;
  x = (x | x << 16) & 0x1f0000ff0000ffull;
  x = (x | x << 8) & 0x100f00f00f00f00full;
  x = (x | x << 4) & 0x10c30c30c30c30c3ull;
  x = (x | x << 2) & 0x1249249249249249ull;
  return x;
}

}  // namespace hilbert3d_internal

// A bijection of the cells onto [0, 2^(3 bits)). REQUIRES: 1 <= bits <= 21 and
// x, y, z < 2^bits. Branch-free: the cells' bits are data, not control flow.
inline uint64_t HilbertKey3(uint32_t x, uint32_t y, uint32_t z, int bits = 21) {
  uint32_t a0 = x, a1 = y, a2 = z;
  const uint32_t m = 1u << (bits - 1);
  for (uint32_t q = m; q > 1; q >>= 1) {  // inverse undo
    const uint32_t p = q - 1;
    // Axis i: if its bit q is set, invert a0's lower bits, else exchange
    // the lower bits of a0 and a_i (a no-op for i = 0).
    auto step = [&](uint32_t& ai) {
      const uint32_t set = 0u - ((ai & q) != 0);
      a0 ^= p & set;
      const uint32_t t = (a0 ^ ai) & p & ~set;
      a0 ^= t;
      ai ^= t;
    };
    a0 ^= p & (0u - ((a0 & q) != 0));
    step(a1);
    step(a2);
  }
  a1 ^= a0;  // Gray encode
  a2 ^= a1;
  uint32_t t = 0;
  for (uint32_t q = m; q > 1; q >>= 1) t ^= (q - 1) & (0u - ((a2 & q) != 0));
  a0 ^= t, a1 ^= t, a2 ^= t;
  // Bit b of axis i goes to key bit 3 b + (2 - i).
  using hilbert3d_internal::Spread3;
  return Spread3(a0) << 2 | Spread3(a1) << 1 | Spread3(a2);
}

// HilbertKey3 of n points at once (out[i] for x[i], y[i], z[i]), the same
// keys: the steps run lane by lane, which the compiler vectorises.
inline void HilbertKeys3(size_t n, const uint32_t* x, const uint32_t* y, const uint32_t* z,
                         uint64_t* out, int bits = 21) {
  constexpr size_t kLanes = 16;
  const uint32_t m = 1u << (bits - 1);
  for (size_t base = 0; base < n; base += kLanes) {
    const size_t lanes = n - base < kLanes ? n - base : kLanes;
    uint32_t a0[kLanes] = {}, a1[kLanes] = {}, a2[kLanes] = {};
    for (size_t j = 0; j < lanes; ++j) a0[j] = x[base + j], a1[j] = y[base + j], a2[j] = z[base + j];
    for (uint32_t q = m; q > 1; q >>= 1) {
      const uint32_t p = q - 1;
      for (size_t j = 0; j < kLanes; ++j) {
        uint32_t b0 = a0[j], b1 = a1[j], b2 = a2[j];
        b0 ^= p & (0u - ((b0 & q) != 0));
        uint32_t set = 0u - ((b1 & q) != 0);
        b0 ^= p & set;
        uint32_t t = (b0 ^ b1) & p & ~set;
        b0 ^= t, b1 ^= t;
        set = 0u - ((b2 & q) != 0);
        b0 ^= p & set;
        t = (b0 ^ b2) & p & ~set;
        b0 ^= t, b2 ^= t;
        a0[j] = b0, a1[j] = b1, a2[j] = b2;
      }
    }
    for (size_t j = 0; j < lanes; ++j) {
      uint32_t b0 = a0[j], b1 = a1[j] ^ b0, b2 = a2[j] ^ b1, t = 0;
      for (uint32_t q = m; q > 1; q >>= 1) t ^= (q - 1) & (0u - ((b2 & q) != 0));
      using hilbert3d_internal::Spread3;
      out[base + j] = Spread3(b0 ^ t) << 2 | Spread3(b1 ^ t) << 1 | Spread3(b2 ^ t);
    }
  }
}

}  // namespace sfc

#endif  // SFCSAMPLER_CORE_HILBERT3D_H_
