#include "cad/face_order.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "core/hilbert3d.h"

namespace sfc::cad {

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
    key[i] = HilbertKey3(quantise(points[i].x, lo.x), quantise(points[i].y, lo.y),
                           quantise(points[i].z, lo.z), kBits);
  }
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return key[a] < key[b]; });
  return order;
}

}  // namespace sfc::cad
