#include "cad/face_order.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <numeric>

namespace sfc::cad {

uint64_t HilbertIndex3(uint32_t x, uint32_t y, uint32_t z, int bits) {
  assert(bits >= 1 && bits <= 21);
  constexpr int kDims = 3;
  uint32_t c[kDims] = {x, y, z};
  const uint32_t top = uint32_t{1} << (bits - 1);
  // Skilling (2004), AxestoTranspose: undo the excess work of the inverse,
  // then Gray-encode; c then holds the index's bits transposed.
  for (uint32_t q = top; q > 1; q >>= 1) {
    const uint32_t p = q - 1;
    for (int i = 0; i < kDims; ++i) {
      if (c[i] & q) {
        c[0] ^= p;
      } else {
        const uint32_t t = (c[0] ^ c[i]) & p;
        c[0] ^= t;
        c[i] ^= t;
      }
    }
  }
  for (int i = 1; i < kDims; ++i) c[i] ^= c[i - 1];
  uint32_t t = 0;
  for (uint32_t q = top; q > 1; q >>= 1) {
    if (c[kDims - 1] & q) t ^= q - 1;
  }
  for (int i = 0; i < kDims; ++i) c[i] ^= t;
  uint64_t h = 0;
  for (int b = bits - 1; b >= 0; --b) {
    for (int i = 0; i < kDims; ++i) h = (h << 1) | ((c[i] >> b) & 1u);
  }
  return h;
}

std::vector<int> HilbertOrder(const std::vector<Vec3>& points) {
  constexpr int kBits = 10;
  const int n = static_cast<int>(points.size());
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  if (n < 2) return order;
  Vec3 lo = points[0], hi = points[0];
  for (const Vec3& p : points) {
    lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
    hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
  }
  // One scale for all axes keeps the cells cubes, so "close in index" means
  // close in space whatever the model's proportions.
  const double extent = std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
  const double cells = double{1 << kBits};
  auto quantise = [&](double value, double origin) {
    if (!(extent > 0)) return uint32_t{0};
    const double c = std::floor((value - origin) / extent * cells);
    return static_cast<uint32_t>(std::clamp(c, 0.0, cells - 1));
  };
  std::vector<uint64_t> key(n);
  for (int i = 0; i < n; ++i) {
    key[i] = HilbertIndex3(quantise(points[i].x, lo.x), quantise(points[i].y, lo.y),
                           quantise(points[i].z, lo.z), kBits);
  }
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return key[a] < key[b]; });
  return order;
}

}  // namespace sfc::cad
