#include "core/leaf_walk.h"

#include <algorithm>
#include <cmath>

namespace sfc {

LeafWalk::LeafWalk(const CurveTree& tree)
    : tree_(tree),
      curve_(tree.curve()),
      grid_(curve_.grid()),
      continuation_levels_(curve_.continuation_levels()),
      continuation_scale_(curve_.PowW(continuation_levels_)),
      continuation_cells_(curve_.PowG(continuation_levels_)),
      inverse_cells_(1 / continuation_cells_),
      total_mass_(tree.total_mass()),
      grade_samples_(std::ldexp(1.0, tree.grade())) {
  int exponent;
  cells_power_of_two_ = std::frexp(continuation_cells_, &exponent) == 0.5;
  last_positive_leaf_ = tree.leaf_count() - 1;
  while (last_positive_leaf_ > 0 &&
         !(tree.mass_end(last_positive_leaf_) > tree.mass_begin(last_positive_leaf_))) {
    --last_positive_leaf_;
  }
}

size_t LeafWalk::LeafFor(double m) const {
  // The first leaf with S_l > m. Leaves before the current one end at or
  // below its S_{l-1}, so from there it is the first such leaf overall.
  const size_t leaves = tree_.leaf_count();
  size_t l = 0;
  if (leaf_ != SIZE_MAX && m >= begin_mass_) {
    l = leaf_;
    // Most samples stay in their leaf or move to the next few.
    for (int step = 0; step < 4 && l < leaves; ++step, ++l) {
      if (tree_.mass_end(l) > m) return l;
    }
  }
  l = tree_.FirstLeafEndingAbove(m, l);
  // q_k S_M can round up to S_M itself: it then belongs to the last leaf with mass.
  return l >= leaves ? last_positive_leaf_ : l;
}

void LeafWalk::Enter(size_t l) {
  leaf_ = l;
  begin_mass_ = tree_.mass_begin(l);
  end_mass_ = tree_.mass_end(l);
  leaf_mass_ = end_mass_ - begin_mass_;
  cell_ = tree_.LeafCell(l);
  leaf_start_ = static_cast<double>(tree_.leaf_start(l));
  leaf_span_ = static_cast<double>(tree_.leaf_end(l) - tree_.leaf_start(l));
  model_ = &tree_.leaf_model(l);
  kind_ = tree_.leaf_model_kind(l);
  warped_ = kind_ == LeafModel::Kind::kQuadratic &&
            (model_->warp[0].power != 1 || model_->warp[1].power != 1);
  // Samples' worth at the tree's grade, not the sequence's count: a
  // progressive set extended on the same tree keeps its prefix.
  samples_ = leaf_mass_ / total_mass_ * grade_samples_;
}

double LeafWalk::PlaceOnAxis(const AxisWarp& w, double x0, double side, double x) {
  if (w.power == 1) return x;
  if (DescendsWarped(w)) return Warp(w, x);  // the curve ran in warped coordinates
  // Uniform in warped coordinates inside the sub-cell [x0, x0 + side].
  const double s0 = Unwarp(w, x0), s1 = Unwarp(w, x0 + side);
  return std::clamp(Warp(w, s0 + (x - x0) / side * (s1 - s0)), x0, x0 + side);
}

template <int kGrid>
bool LeafWalk::Split(Node& node) const {
  // The children's t bounds from the model's exact integrals.
  constexpr int g = kGrid, w = kGrid * kGrid;
  double by_grid[9], share[9], sum = 0;
  SubSquareIntegralsOnGrid<kGrid>(*model_, kind_, node.x0, node.y0, node.side, by_grid);
  for (int c = 0; c < w; ++c) {
    const Curve::Child& ch = curve_.ChildOf(node.state, c);
    share[c] = std::max(0.0, by_grid[ch.dx * g + ch.dy]);
    sum += share[c];
  }
  if (!(sum > 0)) return false;  // the model vanishes here: pure curve bits
  // bounds[c] = t0 + (t1 - t0) * (share[0] + ... + share[c]) / sum, the
  // running sums first so the divisions pair in vector registers.
  double acc[9], fraction[9], running = 0;
  for (int c = 0; c < w; ++c) acc[c] = running += share[c];
  for (int c = 0; c + 1 < w; ++c) fraction[c] = acc[c] / sum;
  for (int c = 0; c + 1 < w; ++c) node.bounds[c] = node.t0 + (node.t1 - node.t0) * fraction[c];
  node.bounds[w - 1] = node.t1;
  node.ordered = true;
  for (int c = 0; c + 1 < w; ++c) node.ordered = node.ordered && node.bounds[c] <= node.bounds[c + 1];
  return true;
}

template <int kArity>
int LeafWalk::ChildHolding(const Node& node, double t) {
  constexpr int w = kArity;
  if (node.ordered) {
    // Bounds in order from t0 up: the first bound above t ends a non-empty
    // interval that holds t. Counted without branches (t falls anywhere).
    int c = 0;
    for (int i = 0; i < w; ++i) c += node.bounds[i] <= t;
    return c;
  }
  double t0 = node.t0;
  for (int c = 0; c < w; ++c) {
    const double t1 = node.bounds[c];
    if (t < t1 && t1 > t0) return c;
    t0 = t1;
  }
  return w;
}

void LeafWalk::Place(const double* m, size_t n, double* u, double* v, double* curve_position) {
  size_t i = 0;
  while (i < n) {
    const size_t l = LeafFor(m[i]);
    if (l != leaf_) Enter(l);
    // The run of samples in this leaf with non-decreasing m. From m[i] on,
    // m < S_l alone puts a sample here.
    size_t j = i + 1;
    while (j < n && m[j] >= m[j - 1] && (m[j] < end_mass_ || LeafFor(m[j]) == l)) ++j;
    double* position = curve_position == nullptr ? nullptr : curve_position + i;
    if (grid_ == 2) {
      PlaceInLeaf<2>(m + i, j - i, u + i, v + i, position);
    } else {
      PlaceInLeaf<3>(m + i, j - i, u + i, v + i, position);
    }
    i = j;
  }
}

template <int kGrid>
void LeafWalk::PlaceInLeaf(const double* m, size_t n, double* u, double* v,
                           double* curve_position) {
  constexpr int g = kGrid, w = kGrid * kGrid;
  t_.resize(n);
  final_.resize(n);
  for (size_t i = 0; i < n; ++i) t_[i] = std::clamp((m[i] - begin_mass_) / leaf_mass_, 0.0, 1.0);

  // Model descent, level by level: a node holding a noticeable part of a
  // sample is split by its model's integrals, and its samples (in t order)
  // go to the children holding them; each sample ends at the deepest node
  // it reaches.
  // nodes_[0, count) are the nodes so far; a level adds at most n (each
  // child holds a sample), so room for n more is made before each level and
  // references stay valid while it runs.
  if (nodes_.size() < n + 1) nodes_.resize(n + 1);
  Node& root = nodes_[0];
  root.t0 = 0, root.t1 = 1, root.x0 = 0, root.y0 = 0, root.side = 1, root.pos = 0, root.span = 1;
  root.state = cell_.state;
  root.depth = 0;
  root.begin = 0, root.end = static_cast<uint32_t>(n);
  size_t count = 1, level_begin = 0;
  while (level_begin < count) {
    const size_t level_end = count;
    if (nodes_.size() < count + n) nodes_.resize(std::max(count + n, 2 * nodes_.size()));
    // The level's splits first: independent of each other and of the samples.
    for (size_t q = level_begin; q < level_end; ++q) {
      Node& node = nodes_[q];
      node.split = node.depth < kMaxModelLevels &&
                   (node.t1 - node.t0) * samples_ >= kNegligibleSamples && Split<kGrid>(node);
    }
    for (size_t q = level_begin; q < level_end; ++q) {
      const Node& node = nodes_[q];
      if (!node.split) {
        for (uint32_t i = node.begin; i < node.end; ++i) final_[i] = static_cast<uint32_t>(q);
        continue;
      }
      const double side = node.side / g, span = node.span / w;
      uint32_t i = node.begin;
      while (i < node.end) {
        const int c = ChildHolding<w>(node, t_[i]);
        if (c == w) {  // rounding left t past the last child: it stays here
          final_[i++] = static_cast<uint32_t>(q);
          continue;
        }
        uint32_t end = i + 1;
        while (end < node.end && ChildHolding<w>(node, t_[end]) == c) ++end;
        const Curve::Child& ch = curve_.ChildOf(node.state, c);
        Node& child = nodes_[count++];
        child.t0 = c == 0 ? node.t0 : node.bounds[c - 1], child.t1 = node.bounds[c];
        child.x0 = node.x0 + ch.dx * side, child.y0 = node.y0 + ch.dy * side, child.side = side;
        child.pos = node.pos + c * span, child.span = span;
        child.state = ch.state;
        child.depth = node.depth + 1;
        child.begin = i, child.end = end;
        i = end;
      }
    }
    level_begin = level_end;
  }

  // Analytic continuation: each sample follows the rest of its t down its
  // node's own curve and sits at the centre of the cell reached.
  const uint64_t scale = continuation_scale_;
  for (size_t i = 0; i < n; ++i) {
    const Node& at = nodes_[final_[i]];
    const double t = t_[i];
    const double tr = at.t1 > at.t0 ? std::clamp((t - at.t0) / (at.t1 - at.t0), 0.0, 1.0) : 0.0;
    // Conversions through int64_t: every value here is below 2^63, so they
    // are exact either way, and the signed ones are single instructions.
    const uint64_t digits = std::min(
        static_cast<uint64_t>(static_cast<int64_t>(tr * static_cast<double>(scale))), scale - 1);
    uint64_t cx, cy;
    int state = at.state;
    curve_.Descend(digits, continuation_levels_, &cx, &cy, &state);
    // For Hilbert the division is by 2^26: a multiplication, with the same bits.
    const double cell = cells_power_of_two_ ? at.side * inverse_cells_ : at.side / continuation_cells_;
    const double x = static_cast<double>(static_cast<int64_t>(cx));
    const double y = static_cast<double>(static_cast<int64_t>(cy));
    double px = at.x0 + (x + 0.5) * cell, py = at.y0 + (y + 0.5) * cell;
    if (warped_) {
      px = PlaceOnAxis(model_->warp[0], at.x0, at.side, px);
      py = PlaceOnAxis(model_->warp[1], at.y0, at.side, py);
    }
    u[i] = cell_.u0 + px * cell_.size;
    v[i] = cell_.v0 + py * cell_.size;
    if (curve_position != nullptr) {
      const double pos = at.pos + tr * at.span;
      curve_position[i] =
          (leaf_start_ + pos * leaf_span_) / static_cast<double>(curve_.Span(0));
    }
  }
}

}  // namespace sfc
