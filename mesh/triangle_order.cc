#include "mesh/triangle_order.h"

#include <algorithm>
#include <cmath>

namespace sfc {
namespace {

struct Item {
  Vec3 c;
  double area;
  uint32_t t;
};

double Coordinate(const Vec3& v, int axis) { return axis == 0 ? v.x : axis == 1 ? v.y : v.z; }

double Distance2(const Vec3& a, const Vec3& b) {
  const Vec3 d = a - b;
  return Dot(d, d);
}

// Orders items by their coordinate along `axis`, ties by triangle index.
bool Before(const Item& a, const Item& b, int axis) {
  const double ca = Coordinate(a.c, axis), cb = Coordinate(b.c, axis);
  return ca < cb || (ca == cb && a.t < b.t);
}

// Rearranges [begin, end) so that its first m items are the m first in the
// order Before, and returns m: the most items, in [1, n - 1], whose areas sum
// to at most `half`. A selection with area weights (expected linear time):
// [begin, lo) holds items known to be in the first part, with area `below`.
size_t SplitByArea(Item* begin, Item* end, int axis, double half) {
  const size_t n = static_cast<size_t>(end - begin);
  Item *lo = begin, *hi = end;
  double below = 0;
  while (lo < hi) {
    // The median of the first, middle and last items as the pivot, moved to hi - 1.
    Item* mid = lo + (hi - lo) / 2;
    if (Before(*mid, *lo, axis)) std::swap(*mid, *lo);
    if (Before(*(hi - 1), *lo, axis)) std::swap(*(hi - 1), *lo);
    if (Before(*mid, *(hi - 1), axis)) std::swap(*mid, *(hi - 1));
    const Item pivot = *(hi - 1);
    Item* store = lo;
    double area = 0;
    for (Item* it = lo; it + 1 < hi; ++it) {
      if (Before(*it, pivot, axis)) {
        area += it->area;
        std::swap(*it, *store++);
      }
    }
    std::swap(*store, *(hi - 1));  // the pivot between the smaller and the larger items
    if (below + area + store->area <= half) {
      below += area + store->area;
      lo = store + 1;
    } else {
      hi = store;
    }
  }
  size_t m = static_cast<size_t>(lo - begin);
  if (m == 0) {  // the first item alone holds more than half
    std::swap(*begin, *std::min_element(begin, end, [axis](const Item& a, const Item& b) {
      return Before(a, b, axis);
    }));
    m = 1;
  } else if (m == n) {
    std::swap(*(end - 1), *std::max_element(begin, end, [axis](const Item& a, const Item& b) {
      return Before(a, b, axis);
    }));
    m = n - 1;
  }
  return m;
}

// Appends the items [begin, end) in curve order, starting near `entry`;
// returns where the order ends (the last centroid).
Vec3 Order(Item* begin, Item* end, Vec3 entry, std::vector<uint32_t>* out) {
  const size_t n = static_cast<size_t>(end - begin);
  if (n == 1) {
    out->push_back(begin->t);
    return begin->c;
  }
  Vec3 lo = begin->c, hi = begin->c;
  for (const Item* it = begin; it != end; ++it) {
    lo = {std::min(lo.x, it->c.x), std::min(lo.y, it->c.y), std::min(lo.z, it->c.z)};
    hi = {std::max(hi.x, it->c.x), std::max(hi.y, it->c.y), std::max(hi.z, it->c.z)};
  }
  const Vec3 extent = hi - lo;
  const int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : extent.y >= extent.z ? 1 : 2;
  double total = 0;
  for (const Item* it = begin; it != end; ++it) total += it->area;
  const size_t split = SplitByArea(begin, end, axis, total / 2);
  Item* middle = begin + split;
  // The half whose area-weighted centre is nearer the curve's end goes first.
  auto centre = [](const Item* b, const Item* e) {
    Vec3 sum{0, 0, 0};
    double weight = 0;
    for (const Item* it = b; it != e; ++it) sum = sum + it->c * it->area, weight += it->area;
    return weight > 0 ? sum * (1 / weight) : b->c;
  };
  if (Distance2(centre(begin, middle), entry) <= Distance2(centre(middle, end), entry)) {
    return Order(middle, end, Order(begin, middle, entry, out), out);
  }
  return Order(begin, middle, Order(middle, end, entry, out), out);
}

}  // namespace

std::vector<uint32_t> CurveOrderOfTriangles(const std::vector<uint32_t>& triangles,
                                            const std::vector<Vec3>& centroid,
                                            const std::vector<double>& area) {
  std::vector<uint32_t> out;
  if (triangles.empty()) return out;
  std::vector<Item> items(triangles.size());
  Vec3 lo = centroid[triangles[0]];
  for (size_t i = 0; i < triangles.size(); ++i) {
    const uint32_t t = triangles[i];
    items[i] = {centroid[t], area[t], t};
    lo = {std::min(lo.x, centroid[t].x), std::min(lo.y, centroid[t].y),
          std::min(lo.z, centroid[t].z)};
  }
  out.reserve(triangles.size());
  // The curve starts at the low corner of the centroids' bounding box.
  Order(items.data(), items.data() + items.size(), lo, &out);
  return out;
}

}  // namespace sfc
