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

// Spreads the low 21 bits of v to every third bit (bit i to bit 3 i): one
// axis of a Morton (Z-order) code, also core/blue_relaxation.cc's grid key.
inline uint64_t Spread3(uint32_t v) {
  uint64_t x = v & 0x1fffffu;
  x = (x | x << 32) & 0x1f00000000ffffull;
  x = (x | x << 16) & 0x1f0000ff0000ffull;
  x = (x | x << 8) & 0x100f00f00f00f00full;
  x = (x | x << 4) & 0x10c30c30c30c30c3ull;
  x = (x | x << 2) & 0x1249249249249249ull;
  return x;
}

namespace hilbert3d_internal {

// One level q of the inverse undo, branch-free: for each axis i, if its bit
// q is set, invert a0's lower bits, else exchange the lower bits of a0 and a_i
// (a no-op for i = 0).
inline void UndoLevel(uint32_t q, uint32_t& a0, uint32_t& a1, uint32_t& a2) {
  const uint32_t p = q - 1;
  auto axis = [&](uint32_t& ai) {
    const uint32_t set = 0u - ((ai & q) != 0);
    a0 ^= p & set;
    const uint32_t t = (a0 ^ ai) & p & ~set;
    a0 ^= t;
    ai ^= t;
  };
  a0 ^= p & (0u - ((a0 & q) != 0));
  axis(a1);
  axis(a2);
}

// Gray-encodes the undone axes and interleaves them: bit b of axis i goes to
// key bit 3 b + (2 - i). m = 2^(bits - 1).
inline uint64_t GrayInterleave(uint32_t m, uint32_t a0, uint32_t a1, uint32_t a2) {
  a1 ^= a0;
  a2 ^= a1;
  uint32_t t = 0;
  for (uint32_t q = m; q > 1; q >>= 1) t ^= (q - 1) & (0u - ((a2 & q) != 0));
  return Spread3(a0 ^ t) << 2 | Spread3(a1 ^ t) << 1 | Spread3(a2 ^ t);
}

}  // namespace hilbert3d_internal

// A bijection of the cells onto [0, 2^(3 bits)). REQUIRES: 1 <= bits <= 21 and
// x, y, z < 2^bits. Branch-free: the cells' bits are data, not control flow.
inline uint64_t HilbertKey3(uint32_t x, uint32_t y, uint32_t z, int bits = 21) {
  const uint32_t m = 1u << (bits - 1);
  for (uint32_t q = m; q > 1; q >>= 1) hilbert3d_internal::UndoLevel(q, x, y, z);
  return hilbert3d_internal::GrayInterleave(m, x, y, z);
}

// HilbertKey3 of n points at once (out[i] for x[i], y[i], z[i]), the same
// keys: each level runs across 16 points, which the compiler vectorises.
inline void HilbertKeys3(size_t n, const uint32_t* x, const uint32_t* y, const uint32_t* z,
                         uint64_t* out, int bits = 21) {
  constexpr size_t kLanes = 16;
  const uint32_t m = 1u << (bits - 1);
  for (size_t base = 0; base < n; base += kLanes) {
    const size_t lanes = n - base < kLanes ? n - base : kLanes;
    uint32_t a0[kLanes] = {}, a1[kLanes] = {}, a2[kLanes] = {};
    for (size_t j = 0; j < lanes; ++j)
      a0[j] = x[base + j], a1[j] = y[base + j], a2[j] = z[base + j];
    for (uint32_t q = m; q > 1; q >>= 1) {
      for (size_t j = 0; j < kLanes; ++j) hilbert3d_internal::UndoLevel(q, a0[j], a1[j], a2[j]);
    }
    for (size_t j = 0; j < lanes; ++j) {
      out[base + j] = hilbert3d_internal::GrayInterleave(m, a0[j], a1[j], a2[j]);
    }
  }
}

}  // namespace sfc

#endif  // SFCSAMPLER_CORE_HILBERT3D_H_
