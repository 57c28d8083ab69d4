#include "mesh/mesh_warp.h"

#include <algorithm>
#include <cmath>

namespace sfc {
namespace {

constexpr double kBelowOne = 1.0 - 0x1.0p-53;
// Halvings past the depth at which nodes hold one leaf's mass on average
// before a node that still straddles leaves is split by mass: the straddling
// nodes' share of the error falls as 2^-kExtraDepth of the leaf level's.
constexpr int kExtraDepth = 12;
// At most 26 halvings of each coordinate, far below the net's 2^-32.
constexpr int kMaxDepth = 52;

// Halves *c at 1/2: the side it falls on, *c rescaled to it (exact).
int Halve(double* c) {
  const int side = *c < 0.5 ? 0 : 1;
  *c = 2 * *c - side;
  return side;
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
}

CurveAddress MeshWarp::Locate(double a, double b) const {
  double c[2] = {std::clamp(a, 0.0, kBelowOne), std::clamp(b, 0.0, kBelowOne)};
  const auto& ends = tree_.mass_ends();
  const double total = tree_.total_mass();
  // The node is the mass interval [t0, t0 + w) x total; the leaves that meet
  // it are lo..hi (the leaves holding its first and last mass).
  double t0 = 0, w = 1;
  auto leaf_at = [&](double t, size_t from, size_t to) {
    // The first leaf in [from, to] whose end passes t x total.
    return static_cast<size_t>(std::upper_bound(ends.begin() + from, ends.begin() + to, t * total) -
                               ends.begin());
  };
  const size_t last = ends.size() - 1;
  size_t lo = leaf_at(0, 0, last), hi = last;
  while (hi > 0 && !(ends[hi] > tree_.mass_begin(hi))) --hi;  // the last leaf with mass
  int axis = 0, depth = 0;
  for (; lo < hi && depth < max_depth_; ++depth) {
    // Dyadic halves of the square hold equal masses: their line is a line of
    // the net's elementary intervals, which every scrambled (0, m, 2)-net
    // fills exactly, whatever the integrand does across it.
    w *= 0.5;
    const double m = (t0 + w) * total;
    if (Halve(&c[axis]) == 0) {  // the last leaf holding mass below m
      hi = static_cast<size_t>(std::lower_bound(ends.begin() + lo, ends.begin() + hi, m) -
                               ends.begin());
    } else {  // the first leaf holding mass above m
      t0 += w, lo = leaf_at(t0, lo, hi);
    }
    axis ^= 1;
  }
  if (lo < hi) {
    // Still across leaves at the depth cap: the coordinate picks the mass.
    const double t = t0 + c[axis] * w;
    const size_t l = leaf_at(t, lo, hi);
    const double begin = std::max(t0 * total, tree_.mass_begin(l));
    const double end = std::min((t0 + w) * total, ends[l]);
    c[axis] = end > begin ? std::clamp((t * total - begin) / (end - begin), 0.0, kBelowOne) : 0.0;
    t0 = begin / total, w = (end - begin) / total;
    lo = hi = l;
  }
  const size_t l = lo;
  const MeshCurveTree::Cell cell = tree_.LeafCell(l);
  // The node's share of the leaf, as fractions of the leaf's mass.
  const double leaf_begin = tree_.mass_begin(l), leaf_mass = ends[l] - leaf_begin;
  const double f0 =
      leaf_mass > 0 ? std::clamp((t0 * total - leaf_begin) / leaf_mass, 0.0, 1.0) : 0.0;
  const double f1 =
      leaf_mass > 0 ? std::clamp(((t0 + w) * total - leaf_begin) / leaf_mass, 0.0, 1.0) : 1.0;
  // The node's share of the leaf: the next coordinate to be halved takes the
  // mass along it, the other the way across.
  double pa, pb;
  PlaceInCell(cell, f0 + c[axis] * (f1 - f0), c[axis ^ 1], &pa, &pb);
  CurveAddress address;
  address.digits = MeshCurveTree::PathOf(pa, pb);
  address.leaf = static_cast<uint32_t>(l);
  address.index = 0;
  return address;
}

}  // namespace sfc
