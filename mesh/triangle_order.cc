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

template <int kAxis>
double Coordinate(const Vec3& v) {
  return kAxis == 0 ? v.x : kAxis == 1 ? v.y : v.z;
}

double Distance2(const Vec3& a, const Vec3& b) {
  const Vec3 d = a - b;
  return Dot(d, d);
}

// Orders items by their coordinate along kAxis, ties by triangle index.
template <int kAxis>
bool Before(const Item& a, const Item& b) {
  const double ca = Coordinate<kAxis>(a.c), cb = Coordinate<kAxis>(b.c);
  return ca < cb || (ca == cb && a.t < b.t);
}

// Rearranges [begin, end) so that its first m items are the m first in the
// order Before, and returns m: the most items, in [1, n - 1], whose areas sum
// to at most `half`. A selection with area weights (expected linear time):
// [begin, lo) holds items known to be in the first part, with area `below`.
// The arrangement it leaves decides the order of later sums, so it is part of
// the curve's definition: change it and meshes' bytes change.
template <int kAxis>
size_t SplitByArea(Item* begin, Item* end, double half) {
  const size_t n = static_cast<size_t>(end - begin);
  Item *lo = begin, *hi = end;
  double below = 0;
  while (lo < hi) {
    // The median of the first, middle and last items as the pivot, moved to hi - 1.
    Item* mid = lo + (hi - lo) / 2;
    if (Before<kAxis>(*mid, *lo)) std::swap(*mid, *lo);
    if (Before<kAxis>(*(hi - 1), *lo)) std::swap(*(hi - 1), *lo);
    if (Before<kAxis>(*mid, *(hi - 1))) std::swap(*mid, *(hi - 1));
    const Item pivot = *(hi - 1);
    Item* store = lo;
    double area = 0;
    for (Item* it = lo; it + 1 < hi; ++it) {
      if (Before<kAxis>(*it, pivot)) {
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
    std::swap(*begin, *std::min_element(begin, end, Before<kAxis>));
    m = 1;
  } else if (m == n) {
    std::swap(*(end - 1), *std::max_element(begin, end, Before<kAxis>));
    m = n - 1;
  }
  return m;
}

size_t SplitByArea(Item* begin, Item* end, int axis, double half) {
  return axis == 0 ? SplitByArea<0>(begin, end, half)
         : axis == 1 ? SplitByArea<1>(begin, end, half)
                     : SplitByArea<2>(begin, end, half);
}

// What Order needs of a run of items, gathered in one pass in the run's
// arrangement: its centroids' bounding box, its area (summed in that order)
// and its area-weighted centroid sum.
struct Summary {
  Vec3 lo, hi, weighted{0, 0, 0};
  double area = 0;
};

Summary Summarize(const Item* begin, const Item* end) {
  Summary s;
  s.lo = s.hi = begin->c;
  for (const Item* it = begin; it != end; ++it) {
    s.lo = {std::min(s.lo.x, it->c.x), std::min(s.lo.y, it->c.y), std::min(s.lo.z, it->c.z)};
    s.hi = {std::max(s.hi.x, it->c.x), std::max(s.hi.y, it->c.y), std::max(s.hi.z, it->c.z)};
    s.weighted = s.weighted + it->c * it->area;
    s.area += it->area;
  }
  return s;
}

// Appends the items [begin, end) in curve order, starting near `entry`;
// returns where the order ends (the last centroid). `run` is
// Summarize(begin, end): the parent's pass over each half serves both the
// choice of which half goes first and the half's own split.
Vec3 Order(Item* begin, Item* end, const Summary& run, Vec3 entry, std::vector<uint32_t>* out) {
  const size_t n = static_cast<size_t>(end - begin);
  if (n == 1) {
    out->push_back(begin->t);
    return begin->c;
  }
  const Vec3 extent = run.hi - run.lo;
  const int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : extent.y >= extent.z ? 1 : 2;
  const size_t split = SplitByArea(begin, end, axis, run.area / 2);
  Item* middle = begin + split;
  const Summary first = Summarize(begin, middle), second = Summarize(middle, end);
  // The half whose area-weighted centre is nearer the curve's end goes first.
  auto centre = [](const Summary& half, const Item* b) {
    return half.area > 0 ? half.weighted * (1 / half.area) : b->c;
  };
  if (Distance2(centre(first, begin), entry) <= Distance2(centre(second, middle), entry)) {
    return Order(middle, end, second, Order(begin, middle, first, entry, out), out);
  }
  return Order(begin, middle, first, Order(middle, end, second, entry, out), out);
}

}  // namespace

std::vector<uint32_t> CurveOrderOfTriangles(const std::vector<uint32_t>& triangles,
                                            const std::vector<Vec3>& centroid,
                                            const std::vector<double>& area) {
  std::vector<uint32_t> out;
  if (triangles.empty()) return out;
  std::vector<Item> items(triangles.size());
  for (size_t i = 0; i < triangles.size(); ++i) {
    const uint32_t t = triangles[i];
    items[i] = {centroid[t], area[t], t};
  }
  out.reserve(triangles.size());
  const Summary all = Summarize(items.data(), items.data() + items.size());
  // The curve starts at the low corner of the centroids' bounding box.
  Order(items.data(), items.data() + items.size(), all, all.lo, &out);
  return out;
}

}  // namespace sfc
