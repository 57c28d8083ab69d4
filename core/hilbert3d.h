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

#include <cstdint>

namespace sfc {

// A bijection of the cells onto [0, 2^(3 bits)). REQUIRES: 1 <= bits <= 21 and
// x, y, z < 2^bits.
inline uint64_t HilbertKey3(uint32_t x, uint32_t y, uint32_t z, int bits = 21) {
  uint32_t a[3] = {x, y, z};
  const uint32_t m = 1u << (bits - 1);
  for (uint32_t q = m; q > 1; q >>= 1) {  // inverse undo
    const uint32_t p = q - 1;
    for (int i = 0; i < 3; ++i) {
      if (a[i] & q) {
        a[0] ^= p;
      } else {
        const uint32_t t = (a[0] ^ a[i]) & p;
        a[0] ^= t;
        a[i] ^= t;
      }
    }
  }
  for (int i = 1; i < 3; ++i) a[i] ^= a[i - 1];  // Gray encode
  uint32_t t = 0;
  for (uint32_t q = m; q > 1; q >>= 1) {
    if (a[2] & q) t ^= q - 1;
  }
  for (int i = 0; i < 3; ++i) a[i] ^= t;
  uint64_t key = 0;
  for (int b = bits - 1; b >= 0; --b) {
    for (int i = 0; i < 3; ++i) key = (key << 1) | ((a[i] >> b) & 1u);
  }
  return key;
}

}  // namespace sfc

#endif  // SFCSAMPLER_CORE_HILBERT3D_H_
