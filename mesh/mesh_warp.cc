#include "mesh/mesh_warp.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstring>
#include <vector>

#include "mesh/mesh_warp_lanes.h"

namespace sfc {
namespace {

using mesh_warp_lanes::kBelowOne;
using mesh_warp_lanes::Spread;

// Halvings past the depth at which nodes hold one leaf's mass on average
// before a node that still straddles leaves is split by mass: the straddling
// nodes' share of the error falls as 2^-kExtraDepth of the leaf level's.
constexpr int kExtraDepth = 12;
// At most 26 halvings of each coordinate, far below the net's 2^-32.
constexpr int kMaxDepth = 52;
// The buckets that start the search for a leaf: 2^(depth + 1) nodes of the
// depth at which nodes hold one leaf on average, at most 2^20 (8 MB).
constexpr int kMaxBucketBits = 20;

// 2^k for |k| <= 1022, exactly: its exponent field (no division).
double Pow2(int k) {
  const uint64_t bits = static_cast<uint64_t>(1023 + k) << 52;
  double x;
  std::memcpy(&x, &bits, sizeof x);
  return x;
}

// The first i < n with e[i] > x (FirstAbove) or e[i] >= x (FirstAtOrAbove),
// n if none, in a sorted e: std::upper_bound's and std::lower_bound's answer
// by a search whose steps are selects, not branches.
template <typename Before>
size_t FirstNotBefore(const double* e, size_t n, double x, const Before& before) {
  if (n == 0) return 0;
  const double* base = e;
  for (size_t len = n; len > 1;) {
    const size_t half = len / 2;
    base = before(base[half - 1], x) ? base + half : base;
    len -= half;
  }
  return static_cast<size_t>(base - e) + (before(*base, x) ? 1 : 0);
}
size_t FirstAbove(const double* e, size_t n, double x) {
  return FirstNotBefore(e, n, x, [](double v, double y) { return v <= y; });
}
size_t FirstAtOrAbove(const double* e, size_t n, double x) {
  return FirstNotBefore(e, n, x, [](double v, double y) { return v < y; });
}

// The u in [0, 1] where the mass of a density linear on [0, 1], from d0 at 0
// to d1 at 1 (both >= 0), reaches `share` of its whole: the root of
// (d1 - d0) u^2 / 2 + d0 u = share (d0 + d1) / 2 in the form that does not
// cancel.
double InvertLinear(double d0, double d1, double share) {
  const double k = (d1 - d0) / 2, c = share * (d0 + d1) / 2;
  const double denominator = d0 + std::sqrt(std::max(0.0, d0 * d0 + 4 * k * c));
  return denominator > 0 ? std::clamp(2 * c / denominator, 0.0, 1.0) : share;
}

// The s in [0, 1] where F(s) = s^2 (q1 + q2 s), not decreasing on [0, 1],
// reaches `share` of F(1): Newton's method in a shrinking bracket, from the
// root of the quadratic part.
double InvertScaled(double q1, double q2, double share) {
  const double target = share * (q1 + q2);
  if (!(q1 + q2 > 0) || q2 == 0) return std::sqrt(share);
  double lo = 0, hi = 1, s = std::sqrt(share);
  for (int iter = 0; iter < 100; ++iter) {
    const double f = s * s * (q1 + q2 * s) - target;
    if (f == 0) return s;
    if (f > 0) {
      hi = s;
    } else {
      lo = s;
    }
    const double d = s * (2 * q1 + 3 * q2 * s);
    double next = d > 0 ? s - f / d : (lo + hi) / 2;
    if (!(next > lo && next < hi)) next = (lo + hi) / 2;
    if (std::fabs(next - s) <= 0x1.0p-50 || hi - lo <= 0x1.0p-52) return next;
    s = next;
  }
  return s;
}

// The point of a leaf cell, in its frame (entry E (0, 0), exit X (1, 0),
// apex A (0, 1)), at the share f in [0, 1) of the cell's mass and g in
// [0, 1). The cell's halves (E, A, M) and (A, X, M), M = (E + X) / 2, take
// f below and above their mass split; each grows from its outer corner (E,
// resp. X) in similar triangles, scaled by s where the mass reaches the
// share, and g is the share along the scaled triangle's far side, from M's
// side to A's. Both halves place g alike on the side A M they share, so the
// map is continuous; a share near 0 or 1 is a small triangle at E or X.
// With the cell's linear density model (values fe, fx, fa at E, X, A) the
// shares are exact.
void PlaceInCell(const MeshCurveTree::Cell& cell, double f, double g, double* pa, double* pb) {
  const double fe = cell.density[0], fx = cell.density[1], fa = cell.density[2];
  const double fm = (fe + fx) / 2;
  const bool uniform = cell.uniform;
  // The halves' masses, exact for the linear model.
  const double m0 = fe + fa + fm, m1 = fa + fx + fm;
  const double split = uniform ? 0.5 : m0 / (m0 + m1);
  const bool first = f < split;
  const double share = first ? f / split : (1 - f) / (1 - split);
  const double fo = first ? fe : fx;  // at the outer corner
  double s, b;
  if (uniform) {
    s = std::sqrt(share), b = g;
  } else {
    // The mass of the half scaled by s about its outer corner O: s^2 times
    // the mean of the model on it, fo + s (fm + fa - 2 fo) / 3.
    s = InvertScaled(fo, (fm + fa - 2 * fo) / 3, share);
    b = InvertLinear(fo + s * (fm - fo), fo + s * (fa - fo), g);
  }
  // O + s ((1 - b) (M - O) + b (A - O)), M = (1/2, 0), A = (0, 1).
  const double ox = first ? 0.0 : 1.0;
  *pa = ox + s * ((1 - b) * (0.5 - ox) + b * (0.0 - ox));
  *pb = s * b;
}

}  // namespace

MeshWarp::MeshWarp(const MeshCurveTree& tree) : tree_(tree) {
  int depth = 0;
  while (depth < 40 && (size_t{1} << depth) < tree.leaf_count()) ++depth;
  max_depth_ = std::min(depth + kExtraDepth, kMaxDepth);
  uniform_density_ = tree.density().uniform();
  // Leaves are numbered by 32 bits (CurveAddress::leaf): nodes are never
  // narrower than 2^-44, which LocateInLeaf's search needs.
  assert(max_depth_ <= 44);
  // The buckets: node j of depth bucket_bits_ meets leaves FirstAbove(its
  // begin) .. FirstAtOrAbove(its end), and every node inside it a sub-range.
  // Two pointers walk the leaves once.
  bucket_bits_ = std::min(max_depth_, std::min(depth + 1, kMaxBucketBits));
  const size_t buckets = size_t{1} << bucket_bits_;
  const auto& ends = tree.mass_ends();
  const double total = tree.total_mass();
  bucket_leaves_.resize(2 * buckets);
  size_t first = 0, last = 0;
  for (size_t j = 0; j < buckets; ++j) {
    const double begin = std::ldexp(static_cast<double>(j), -bucket_bits_) * total;
    const double end = std::ldexp(static_cast<double>(j + 1), -bucket_bits_) * total;
    while (first < ends.size() && ends[first] <= begin) ++first;
    while (last < ends.size() && ends[last] < end) ++last;
    bucket_leaves_[2 * j] = static_cast<uint32_t>(first);
    bucket_leaves_[2 * j + 1] = static_cast<uint32_t>(last);
  }
}

void MeshWarp::LocateInLeaf(double a, double b, size_t* leaf, double* pa, double* pb) const {
  double f, g;
  LeafShare(a, b, leaf, &f, &g);
  // PlaceInCell reads the cell's density model alone: under a uniform
  // density every cell's is the default (uniform), with no cell to decode.
  PlaceInCell(uniform_density_ ? MeshCurveTree::Cell{} : tree_.LeafCell(*leaf), f, g, pa, pb);
}

void MeshWarp::LeafShare(double a, double b, size_t* leaf, double* f, double* g) const {
  double c[2] = {std::clamp(a, 0.0, kBelowOne), std::clamp(b, 0.0, kBelowOne)};
  const auto& ends = tree_.mass_ends();
  const double total = tree_.total_mass();
  // The node is the mass interval [t0, t0 + w) x total. Dyadic halves of the
  // square hold equal masses: their line is a line of the net's elementary
  // intervals, which every scrambled (0, m, 2)-net fills exactly, whatever
  // the integrand does across it. The node at depth d holds the point whose
  // top bits, the first coordinate's at even depths and the second's at odd
  // ones, interleaved, are the top d bits of t0 (and c is what is left of
  // each coordinate below them). The leaves that meet a node are lo..hi, the
  // leaves holding its first and last mass: lo the first leaf ending above
  // t0 x total, hi the first ending at or above (t0 + w) x total; both move
  // inward as nodes nest (their ends differ by far more than their rounding:
  // w >= 2^-44). The halving stops at the first node inside one leaf, or at
  // the depth cap: the leaves of the node at the cap are found first, then
  // the depth where the node's lo and hi first meet, by bisection.
  const int bits_a = (max_depth_ + 1) / 2, bits_b = max_depth_ / 2;
  const uint64_t top_a = Spread(static_cast<uint64_t>(c[0] * Pow2(bits_a)));
  const uint64_t top_b = Spread(static_cast<uint64_t>(c[1] * Pow2(bits_b)));
  const uint64_t cap_node = max_depth_ % 2 == 0 ? top_a << 1 | top_b : top_a | top_b << 1;
  // The node of depth d: t0, and t0 + w (exact dyadic values).
  auto begin_at = [&](int d) {
    return static_cast<double>(cap_node >> (max_depth_ - d)) * Pow2(-d);
  };
  auto end_at = [&](int d) {
    return static_cast<double>((cap_node >> (max_depth_ - d)) + 1) * Pow2(-d);
  };
  // Both lie among the leaves that meet the cap node's bucket.
  const size_t bucket = static_cast<size_t>(cap_node >> (max_depth_ - bucket_bits_));
  const size_t from = bucket_leaves_[2 * bucket], to = bucket_leaves_[2 * bucket + 1] + size_t{1};
  size_t lo = from + FirstAbove(ends.data() + from, to - from, begin_at(max_depth_) * total);
  size_t hi = from + FirstAtOrAbove(ends.data() + from, to - from, end_at(max_depth_) * total);
  int depth = max_depth_;
  if (lo == hi) {
    // The first depth whose node holds mass of leaf lo alone: t0 x total >=
    // lo's begin and (t0 + w) x total <= lo's end, false and then true.
    const double lo_begin = tree_.mass_begin(lo), lo_end = ends[lo];
    int shallow = 0;
    while (shallow < depth) {
      const int mid = (shallow + depth) / 2;
      if (begin_at(mid) * total >= lo_begin && end_at(mid) * total <= lo_end) {
        depth = mid;
      } else {
        shallow = mid + 1;
      }
    }
  }
  // What is left of each coordinate below the node's bits (exact).
  const double scaled_a = c[0] * Pow2((depth + 1) / 2), scaled_b = c[1] * Pow2(depth / 2);
  c[0] = scaled_a - std::floor(scaled_a), c[1] = scaled_b - std::floor(scaled_b);
  const int axis = depth % 2;
  double t0 = begin_at(depth), w = Pow2(-depth);
  if (lo < hi) {
    // Still across leaves at the depth cap: the coordinate picks the mass.
    const double t = t0 + c[axis] * w;
    const size_t l = static_cast<size_t>(
        std::upper_bound(ends.begin() + lo, ends.begin() + hi, t * total) - ends.begin());
    const double begin = std::max(t0 * total, tree_.mass_begin(l));
    const double end = std::min((t0 + w) * total, ends[l]);
    c[axis] = end > begin ? std::clamp((t * total - begin) / (end - begin), 0.0, kBelowOne) : 0.0;
    t0 = begin / total, w = (end - begin) / total;
    lo = hi = l;
  }
  const size_t l = lo;
  // The node's share of the leaf, as fractions of the leaf's mass.
  const double leaf_begin = tree_.mass_begin(l), leaf_mass = ends[l] - leaf_begin;
  const double f0 =
      leaf_mass > 0 ? std::clamp((t0 * total - leaf_begin) / leaf_mass, 0.0, 1.0) : 0.0;
  const double f1 =
      leaf_mass > 0 ? std::clamp(((t0 + w) * total - leaf_begin) / leaf_mass, 0.0, 1.0) : 1.0;
  // The node's share of the leaf: the next coordinate to be halved takes the
  // mass along it, the other the way across.
  *f = f0 + c[axis] * (f1 - f0);
  *g = c[axis ^ 1];
  *leaf = l;
}

void MeshWarp::LocateMany(size_t n, const double* a, const double* b, CurveAddress* out,
                          math::VectorPath path) const {
  constexpr size_t kBatch = 64;
  double pa[kBatch], pb[kBatch], f[kBatch], g[kBatch];
  int64_t leaf[kBatch], across[kBatch];
  uint64_t paths[kBatch];
  const mesh_warp_lanes::LeafTables tables{tree_.mass_ends().data(), bucket_leaves_.data(),
                                           tree_.total_mass(), max_depth_, bucket_bits_};
  using math::VectorPath;
  for (size_t i0 = 0; i0 < n; i0 += kBatch) {
    const size_t m = std::min(kBatch, n - i0);
    if (path == math::VectorPath::kScalar) {
      // The reference: one point at a time.
      for (size_t i = 0; i < m; ++i) {
        size_t l;
        LocateInLeaf(a[i0 + i], b[i0 + i], &l, &pa[i], &pb[i]);
        leaf[i] = static_cast<int64_t>(l);
      }
    } else {
      if (path == VectorPath::kAvx512) {
        mesh_warp_lanes::LeafSharesAvx512(tables, m, a + i0, b + i0, leaf, f, g, across);
      } else if (path == VectorPath::kAvx2) {
        mesh_warp_lanes::LeafSharesAvx2(tables, m, a + i0, b + i0, leaf, f, g, across);
      } else if (path == VectorPath::kAvx) {
        mesh_warp_lanes::LeafSharesAvx(tables, m, a + i0, b + i0, leaf, f, g, across);
      } else {
        mesh_warp_lanes::LeafSharesOf(tables, m, a + i0, b + i0, leaf, f, g, across);
      }
      if (uniform_density_) {
        if (path == VectorPath::kAvx512) {
          mesh_warp_lanes::PlaceUniformAvx512(m, f, g, pa, pb);
        } else if (path == VectorPath::kAvx2) {
          mesh_warp_lanes::PlaceUniformAvx2(m, f, g, pa, pb);
        } else if (path == VectorPath::kAvx) {
          mesh_warp_lanes::PlaceUniformAvx(m, f, g, pa, pb);
        } else {
          mesh_warp_lanes::PlaceUniformOf(m, f, g, pa, pb);
        }
      }
      for (size_t i = 0; i < m; ++i) {
        if (across[i] != 0) {  // rare: a node across leaves at the depth cap
          size_t l;
          LocateInLeaf(a[i0 + i], b[i0 + i], &l, &pa[i], &pb[i]);
          leaf[i] = static_cast<int64_t>(l);
        } else if (!uniform_density_) {
          PlaceInCell(tree_.LeafCell(static_cast<size_t>(leaf[i])), f[i], g[i], &pa[i], &pb[i]);
        }
      }
    }
    PathsOf(m, pa, pb, paths, path);
    for (size_t i = 0; i < m; ++i) {
      out[i0 + i].leaf = static_cast<uint32_t>(leaf[i]);
      out[i0 + i].index = 0;
      out[i0 + i].digits = paths[i];
    }
  }
}

void MeshWarp::PathsOf(size_t n, const double* pa, const double* pb, uint64_t* paths,
                       math::VectorPath path) {
  if (path == math::VectorPath::kScalar) {
    for (size_t i = 0; i < n; ++i) paths[i] = MeshCurveTree::PathOf(pa[i], pb[i]);
  } else if (path == math::VectorPath::kAvx512) {
    mesh_warp_lanes::PathsOfAvx512(n, pa, pb, paths);
  } else if (path == math::VectorPath::kAvx2) {
    mesh_warp_lanes::PathsOfAvx2(n, pa, pb, paths);
  } else if (path == math::VectorPath::kAvx) {
    mesh_warp_lanes::PathsOfAvx(n, pa, pb, paths);
  } else {
    mesh_warp_lanes::PathsOfLanes(n, pa, pb, paths);
  }
}

}  // namespace sfc
