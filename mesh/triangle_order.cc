#include "mesh/triangle_order.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "base/worker_pool.h"

namespace sfc {
namespace {

struct Item {
  Vec3 c;
  double area;
  uint32_t t;
};

double Distance2(const Vec3& a, const Vec3& b) {
  const Vec3 d = a - b;
  return Dot(d, d);
}

// Meshes with fewer triangles are ordered on one thread.
constexpr size_t kParallelItems = 16384;

// The items stay where they are; the recursion arranges indices into them
// (4 bytes to swap instead of 40).
using Index = uint32_t;

// Orders items by their coordinate along kAxis, ties by triangle index.
template <int kAxis>
struct Before {
  const Item* items;
  bool operator()(Index a, Index b) const {
    const double ca = Coordinate(items[a].c), cb = Coordinate(items[b].c);
    // Bitwise, not short-circuit: no branch for the partition to mispredict.
    return (ca < cb) | ((ca == cb) & (items[a].t < items[b].t));
  }
  static double Coordinate(const Vec3& v) { return kAxis == 0 ? v.x : kAxis == 1 ? v.y : v.z; }
};

// Rearranges [begin, end) so that its first m items are the m first in the
// order Before, and returns m: the most items, in [1, n - 1], whose areas sum
// to at most `half`. A selection with area weights (expected linear time):
// [begin, lo) holds items known to be in the first part, with area `below`.
// The arrangement it leaves decides the order of later sums, so it is part of
// the curve's definition: change it and meshes' bytes change.
template <int kAxis>
size_t SplitByArea(const Item* items, Index* begin, Index* end, double half) {
  const Before<kAxis> before{items};
  const size_t n = static_cast<size_t>(end - begin);
  // What the general steps below come to for two and three items: the items
  // sorted by Before; two split 1 + 1 whatever the areas, and of three the
  // first two go to the first part when their areas, added in that order, are
  // at most `half` (the median of three is the pivot; one or two more rounds
  // settle m).
  if (n == 2) {
    if (before(begin[1], begin[0])) std::swap(begin[0], begin[1]);
    return 1;
  }
  if (n == 3) {
    if (before(begin[1], begin[0])) std::swap(begin[0], begin[1]);
    if (before(begin[2], begin[1])) std::swap(begin[1], begin[2]);
    if (before(begin[1], begin[0])) std::swap(begin[0], begin[1]);
    return items[begin[0]].area + items[begin[1]].area <= half ? 2 : 1;
  }
  Index *lo = begin, *hi = end;
  double below = 0;
  while (lo < hi) {
    // The median of the first, middle and last items as the pivot, moved to hi - 1.
    Index* mid = lo + (hi - lo) / 2;
    if (before(*mid, *lo)) std::swap(*mid, *lo);
    if (before(*(hi - 1), *lo)) std::swap(*(hi - 1), *lo);
    if (before(*mid, *(hi - 1))) std::swap(*mid, *(hi - 1));
    const Index pivot = *(hi - 1);
    // Lomuto's partition: each item before the pivot is swapped to `store`.
    // Written without branches (the comparisons are coin flips to a branch
    // predictor); it makes the same arrangement as the branching form.
    Index* store = lo;
    for (Index* it = lo; it + 1 < hi; ++it) {
      const Index a = *it, b = *store;
      const Index smaller = before(a, pivot);
      const Index keep = smaller - 1;  // all ones when not smaller
      *store = (a & ~keep) | (b & keep);
      *it = (b & ~keep) | (a & keep);
      store += smaller;
    }
    // The smaller items' area, summed in the order they were found (Lomuto
    // keeps that order).
    double area = 0;
    for (const Index* it = lo; it != store; ++it) area += items[*it].area;
    std::swap(*store, *(hi - 1));  // the pivot between the smaller and the larger items
    if (below + area + items[*store].area <= half) {
      below += area + items[*store].area;
      lo = store + 1;
    } else {
      hi = store;
    }
  }
  size_t m = static_cast<size_t>(lo - begin);
  if (m == 0) {  // the first item alone holds more than half
    std::swap(*begin, *std::min_element(begin, end, before));
    m = 1;
  } else if (m == n) {
    std::swap(*(end - 1), *std::max_element(begin, end, before));
    m = n - 1;
  }
  return m;
}

size_t SplitByArea(const Item* items, Index* begin, Index* end, int axis, double half) {
  return axis == 0 ? SplitByArea<0>(items, begin, end, half)
         : axis == 1 ? SplitByArea<1>(items, begin, end, half)
                     : SplitByArea<2>(items, begin, end, half);
}

// What Order needs of a run of items, gathered in one pass in the run's
// arrangement: its centroids' bounding box, its area (summed in that order)
// and its area-weighted centroid sum.
struct Summary {
  Vec3 lo, hi, weighted{0, 0, 0};
  double area = 0;
};

Summary Summarize(const Item* items, const Index* begin, const Index* end) {
  Summary s;
  s.lo = s.hi = items[*begin].c;
  for (const Index* i = begin; i != end; ++i) {
    const Item& it = items[*i];
    s.lo = {std::min(s.lo.x, it.c.x), std::min(s.lo.y, it.c.y), std::min(s.lo.z, it.c.z)};
    s.hi = {std::max(s.hi.x, it.c.x), std::max(s.hi.y, it.c.y), std::max(s.hi.z, it.c.z)};
    s.weighted = s.weighted + it.c * it.area;
    s.area += it.area;
  }
  return s;
}

// The centre a half of a split is compared by in Order and Walk: its
// area-weighted centroid, or its first item's centroid when it has no area.
Vec3 Centre(const Item* items, const Summary& half, const Index* first) {
  return half.area > 0 ? half.weighted * (1 / half.area) : items[*first].c;
}

// Appends the items [begin, end) in curve order, starting near `entry`;
// returns where the order ends (the last centroid). `run` is
// Summarize(begin, end): the parent's pass over each half serves both the
// choice of which half goes first and the half's own split.
Vec3 Order(const Item* items, Index* begin, Index* end, const Summary& run, Vec3 entry,
           std::vector<uint32_t>* out) {
  const size_t n = static_cast<size_t>(end - begin);
  if (n == 1) {
    out->push_back(items[*begin].t);
    return items[*begin].c;
  }
  const Vec3 extent = run.hi - run.lo;
  const int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : extent.y >= extent.z ? 1 : 2;
  const size_t split = SplitByArea(items, begin, end, axis, run.area / 2);
  Index* middle = begin + split;
  const Summary first = Summarize(items, begin, middle), second = Summarize(items, middle, end);
  // The half whose area-weighted centre is nearer the curve's end goes first.
  if (Distance2(Centre(items, first, begin), entry) <=
      Distance2(Centre(items, second, middle), entry)) {
    return Order(items, middle, end, second, Order(items, begin, middle, first, entry, out), out);
  }
  return Order(items, begin, middle, first, Order(items, middle, end, second, entry, out), out);
}

// On threads, Order's work in two passes. Where a run splits does not depend
// on where the curve enters it (only which half Order visits first does), so
// the splits of disjoint runs are made at once (Split) into a bisection
// tree, and one pass over it then chooses the order (Walk): the same order.
// A run's node is numbered in preorder: its first half's is k + 1, its
// second half's k + (the first half's items).
struct Node {
  uint32_t split;  // the first half's items
  Vec3 centre[2];  // of the halves, as the split left them
};

// A run of items [begin, end) still to split, its Summary and its node.
struct Run {
  Index* begin;
  Index* end;
  Summary summary;
  size_t k;
};

// Splits `run` as Order does into node run.k and its two halves; false for a
// run of one item (a leaf: no node).
bool SplitOnce(const Item* items, const Run& run, Node* nodes, Run* first, Run* second) {
  const size_t n = static_cast<size_t>(run.end - run.begin);
  if (n == 1) return false;
  const Vec3 extent = run.summary.hi - run.summary.lo;
  const int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : extent.y >= extent.z ? 1 : 2;
  const size_t split = SplitByArea(items, run.begin, run.end, axis, run.summary.area / 2);
  Index* middle = run.begin + split;
  *first = {run.begin, middle, Summarize(items, run.begin, middle), run.k + 1};
  *second = {middle, run.end, Summarize(items, middle, run.end), run.k + split};
  nodes[run.k] = {static_cast<uint32_t>(split),
                  {Centre(items, first->summary, run.begin),
                   Centre(items, second->summary, middle)}};
  return true;
}

// Splits `run` into node run.k and every node below it.
void Split(const Item* items, const Run& run, Node* nodes) {
  Run first, second;
  if (!SplitOnce(items, run, nodes, &first, &second)) return;
  Split(items, first, nodes);
  Split(items, second, nodes);
}

// The same on the process's worker pool: the top `levels` levels a level at
// a time, each level's runs in parallel, then the 2^levels runs below.
void SplitInParallel(const Item* items, const Run& all, int levels, Node* nodes) {
  std::vector<Run> runs{all};
  for (int level = 0; level < levels && !runs.empty(); ++level) {
    std::vector<Run> halves(2 * runs.size());
    std::vector<char> split(runs.size(), 0);
    WorkerPool::Shared().ParallelFor(static_cast<int>(runs.size()), [&](int i) {
      split[i] = SplitOnce(items, runs[i], nodes, &halves[2 * i], &halves[2 * i + 1]);
    });
    std::vector<Run> next;
    for (size_t i = 0; i < runs.size(); ++i) {
      if (split[i]) next.push_back(halves[2 * i]), next.push_back(halves[2 * i + 1]);
    }
    runs.swap(next);
  }
  WorkerPool::Shared().ParallelFor(static_cast<int>(runs.size()),
                                   [&](int i) { Split(items, runs[i], nodes); });
}

// Order's choice of which half goes first, on Split's tree (node k holds
// the items [begin, end)).
Vec3 Walk(const Item* items, const Index* begin, const Index* end, size_t k, const Node* nodes,
          Vec3 entry, std::vector<uint32_t>* out) {
  if (end - begin == 1) {
    out->push_back(items[*begin].t);
    return items[*begin].c;
  }
  const Node& node = nodes[k];
  const Index* middle = begin + node.split;
  if (Distance2(node.centre[0], entry) <= Distance2(node.centre[1], entry)) {
    return Walk(items, middle, end, k + node.split, nodes,
                Walk(items, begin, middle, k + 1, nodes, entry, out), out);
  }
  return Walk(items, begin, middle, k + 1, nodes,
              Walk(items, middle, end, k + node.split, nodes, entry, out), out);
}

}  // namespace

std::vector<uint32_t> CurveOrderOfTriangles(const std::vector<uint32_t>& triangles,
                                            const std::vector<Vec3>& centroid,
                                            const std::vector<double>& area, int threads) {
  std::vector<uint32_t> out;
  if (triangles.empty()) return out;
  std::vector<Item> items(triangles.size());
  for (size_t i = 0; i < triangles.size(); ++i) {
    const uint32_t t = triangles[i];
    items[i] = {centroid[t], area[t], t};
  }
  out.reserve(triangles.size());
  std::vector<Index> arrangement(items.size());
  for (size_t i = 0; i < items.size(); ++i) arrangement[i] = static_cast<Index>(i);
  Index* begin = arrangement.data();
  Index* end = begin + arrangement.size();
  const Summary all = Summarize(items.data(), begin, end);
  // The worker pool splits the top levels' halves, up to 2^spawn runs at
  // once; none for a mesh too small to repay it.
  int spawn = 0;
  while ((1 << spawn) < threads && spawn < 6) ++spawn;
  // The curve starts at the low corner of the centroids' bounding box.
  if (spawn == 0 || items.size() < kParallelItems) {
    Order(items.data(), begin, end, all, all.lo, &out);
    return out;
  }
  std::vector<Node> nodes(items.size() - 1);
  SplitInParallel(items.data(), {begin, end, all, 0}, spawn, nodes.data());
  Walk(items.data(), begin, end, 0, nodes.data(), all.lo, &out);
  return out;
}

}  // namespace sfc
