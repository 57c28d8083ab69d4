#include "mesh/mesh_warp.h"

#include <algorithm>
#include <cmath>

namespace sfc {
namespace {

// Bisection levels below a leaf that an address holds (MeshCurveTree's
// kLevels: all the bits of a sample's fraction).
constexpr int kLevels = 52;
constexpr double kBelowOne = 1.0 - 0x1.0p-53;

// Picks the half of a split that *c falls in and rescales *c to it.
int Pick(double split, const double inverse[2], double* c) {
  const int side = *c < split ? 0 : 1;
  *c = std::clamp((side == 0 ? *c : *c - split) * inverse[side], 0.0, kBelowOne);
  return side;
}

}  // namespace

MeshWarp::MeshWarp(const MeshCurveTree& tree) : tree_(tree) {
  nodes_.reserve(tree.leaf_count());
  root_ = Build(0, tree.leaf_count());
}

int32_t MeshWarp::Build(size_t lo, size_t hi) {
  if (hi - lo == 1) return -static_cast<int32_t>(lo) - 1;
  const auto& ends = tree_.mass_ends();
  const double begin = tree_.mass_begin(lo), end = ends[hi - 1];
  // The first leaf whose end reaches half the node's mass closes the first
  // half; each half keeps at least one leaf.
  const size_t j =
      std::lower_bound(ends.begin() + lo, ends.begin() + (hi - 1), begin + (end - begin) / 2) -
      ends.begin();
  const size_t mid = std::clamp(j + 1, lo + 1, hi - 1);
  const int32_t index = static_cast<int32_t>(nodes_.size());
  nodes_.push_back({});
  const int32_t left = Build(lo, mid);
  const int32_t right = Build(mid, hi);
  Node& node = nodes_[index];
  node.child[0] = left, node.child[1] = right;
  const double first = tree_.mass_begin(mid) - begin, second = end - tree_.mass_begin(mid);
  const double total = first + second;
  node.split = !(first > 0) ? 0.0 : !(second > 0) ? 1.0 : first / total;
  node.inverse[0] = first > 0 ? total / first : 0;
  node.inverse[1] = second > 0 ? total / second : 0;
  return index;
}

CurveAddress MeshWarp::Locate(double a, double b) const {
  double c[2] = {std::clamp(a, 0.0, kBelowOne), std::clamp(b, 0.0, kBelowOne)};
  int axis = 0;  // the coordinate the next split takes
  int32_t ref = root_;
  while (ref >= 0) {
    const Node& node = nodes_[ref];
    ref = node.child[Pick(node.split, node.inverse, &c[axis])];
    axis ^= 1;
  }
  const size_t l = static_cast<size_t>(-ref - 1);
  const MeshCurveTree::Cell cell = tree_.LeafCell(l);
  // Down the cell's bisection while its linear model varies (the test of
  // MeshCurveTree::Descend), by the model's values at the current cell's
  // entry, exit and apex.
  double fe = cell.density[0], fx = cell.density[1], fa = cell.density[2];
  uint64_t path = 0;
  int level = 0;
  if (!cell.uniform) {
    for (; level < kLevels; ++level) {
      const double lo = std::min({fe, fx, fa}), hi = std::max({fe, fx, fa});
      if (hi - lo <= std::ldexp(hi, level / 2 - 26)) break;
      const double fm = (fe + fx) * 0.5;
      // Exact integrals of the linear model over the two equal-area children.
      const double m0 = fe + fa + fm, m1 = fa + fx + fm;
      const double total = m0 + m1;
      const double split = !(m0 > 0) ? 0.0 : !(m1 > 0) ? 1.0 : m0 / total;
      const double inverse[2] = {m0 > 0 ? total / m0 : 0, m1 > 0 ? total / m1 : 0};
      const int side = Pick(split, inverse, &c[axis]);
      axis ^= 1;
      path = path << 1 | side;
      if (side == 0) {  // (E, A, M)
        fx = fa;
      } else {  // (A, X, M)
        fe = fa;
      }
      fa = fm;
    }
  }
  // The area-preserving map of the square onto the current cell, in its own
  // frame (entry (0, 0), exit (1, 0), apex (0, 1)); then the point's
  // remaining bisection choices, each child's frame mapped back by the
  // inverse of MeshCurveTree's T0, T1.
  const double s = std::sqrt(c[0]);
  double pa = s * (1 - c[1]), pb = s * c[1];
  for (; level < kLevels; ++level) {
    if (2 * pa + pb < 1) {  // child (E, A, M): frame (a, b) -> (b, 2a)
      const double na = pb, nb = 2 * pa;
      pa = na, pb = nb;
      path <<= 1;
    } else {  // child (A, X, M): (a, b) -> (2a + b - 1, 2 (1 - a - b))
      const double na = 2 * pa + pb - 1, nb = 2 * (1 - pa - pb);
      pa = na, pb = nb;
      path = path << 1 | 1;
    }
    pa = std::clamp(pa, 0.0, 1.0), pb = std::clamp(pb, 0.0, 1.0 - pa);
  }
  CurveAddress address;
  address.digits = path;
  address.leaf = static_cast<uint32_t>(l);
  address.index = 0;
  return address;
}

void MeshWarp::Place(const CurveAddress& at, MeshCurveTree::Cell* cell, std::array<double, 3>* bary,
                     double* area_position) const {
  *cell = tree_.LeafCell(at.leaf);
  // The digits are the sub-cell's bisection choices: decoded as in a
  // uniform cell, whose choices are the digits of its fraction.
  MeshCurveTree::Cell geometric = *cell;
  geometric.uniform = true;
  MeshCurveTree::Descend(geometric, std::ldexp(static_cast<double>(at.digits), -kLevels), bary,
                         area_position);
}

}  // namespace sfc
