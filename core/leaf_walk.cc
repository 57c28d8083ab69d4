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
      total_mass_(tree.total_mass()),
      grade_samples_(std::ldexp(1.0, tree.grade())) {
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
  leaf_mass_ = tree_.mass_end(l) - begin_mass_;
  cell_ = tree_.LeafCell(l);
  leaf_start_ = static_cast<double>(tree_.leaf_start(l));
  leaf_span_ = static_cast<double>(tree_.leaf_end(l) - tree_.leaf_start(l));
  model_ = &tree_.leaf_model(l);
  kind_ = tree_.leaf_model_kind(l);
  // Samples' worth at the tree's grade, not the sequence's count: a
  // progressive set extended on the same tree keeps its prefix.
  samples_ = leaf_mass_ / total_mass_ * grade_samples_;
  depth_ = 0;
  Level& root = stack_[0];
  root.t0 = 0, root.t1 = 1, root.x0 = 0, root.y0 = 0, root.side = 1, root.pos = 0, root.span = 1;
  root.state = cell_.state;
  root.children = 0;
}

template <int kGrid>
bool LeafWalk::Split(Level& top) const {
  // The children's t bounds from the model's exact integrals, once per level.
  constexpr int g = kGrid, w = kGrid * kGrid;
  double by_grid[9], share[9], sum = 0;
  SubSquareIntegralsOnGrid<kGrid>(*model_, kind_, top.x0, top.y0, top.side, by_grid);
  for (int c = 0; c < w; ++c) {
    const Curve::Child& ch = curve_.ChildOf(top.state, c);
    share[c] = std::max(0.0, by_grid[ch.dx * g + ch.dy]);
    sum += share[c];
  }
  if (!(sum > 0)) return false;  // the model vanishes here: pure curve bits
  double acc = 0;
  for (int c = 0; c < w; ++c) {
    acc += share[c];
    top.bounds[c] = c + 1 == w ? top.t1 : top.t0 + (top.t1 - top.t0) * (acc / sum);
  }
  top.children = w;
  top.ordered = true;
  for (int c = 0; c + 1 < w; ++c) top.ordered = top.ordered && top.bounds[c] <= top.bounds[c + 1];
  return true;
}

template <int kArity>
int LeafWalk::ChildHolding(const Level& top, double t) const {
  constexpr int w = kArity;
  if (top.ordered) {
    // Bounds in order from t0 up: the first bound above t ends a non-empty
    // interval that holds t. Counted without branches (t falls anywhere).
    int c = 0;
    for (int i = 0; i < w; ++i) c += top.bounds[i] <= t;
    return c;
  }
  double t0 = top.t0;
  for (int c = 0; c < w; ++c) {
    const double t1 = top.bounds[c];
    if (t < t1 && t1 > t0) return c;
    t0 = t1;
  }
  return w;
}

void LeafWalk::Place(const double* m, size_t n, double* u, double* v, double* curve_position) {
  if (grid_ == 2) {
    PlaceOnGrid<2>(m, n, u, v, curve_position);
  } else {
    PlaceOnGrid<3>(m, n, u, v, curve_position);
  }
}

template <int kGrid>
void LeafWalk::PlaceOnGrid(const double* m, size_t n, double* u, double* v,
                           double* curve_position) {
  constexpr int g = kGrid, w = kGrid * kGrid;
  for (size_t i = 0; i < n; ++i) {
    const size_t l = LeafFor(m[i]);
    if (l != leaf_) Enter(l);
    const double t = std::clamp((m[i] - begin_mass_) / leaf_mass_, 0.0, 1.0);

    // Model descent: pop to the deepest level holding t, then descend while
    // the sub-cell carries a noticeable part of a sample.
    while (depth_ > 0 && !(t >= stack_[depth_].t0 && t < stack_[depth_].t1)) --depth_;
    while (depth_ < kMaxModelLevels &&
           (stack_[depth_].t1 - stack_[depth_].t0) * samples_ >= kNegligibleSamples) {
      Level& top = stack_[depth_];
      if (top.children == 0 && !Split<kGrid>(top)) break;
      const int c = ChildHolding<w>(top, t);
      if (c == w) break;  // rounding left t past the last child: stay here
      const Curve::Child& ch = curve_.ChildOf(top.state, c);
      const double side = top.side / g, span = top.span / w;
      Level& child = stack_[++depth_];
      child.t0 = c == 0 ? top.t0 : top.bounds[c - 1], child.t1 = top.bounds[c];
      child.x0 = top.x0 + ch.dx * side, child.y0 = top.y0 + ch.dy * side, child.side = side;
      child.pos = top.pos + c * span, child.span = span;
      child.state = ch.state;
      child.children = 0;
    }
    const Level& at = stack_[depth_];
    const double tr = at.t1 > at.t0 ? std::clamp((t - at.t0) / (at.t1 - at.t0), 0.0, 1.0) : 0.0;

    // Analytic continuation: follow the rest of t down the sub-cell's own curve.
    const uint64_t scale = continuation_scale_;
    const uint64_t digits =
        std::min(static_cast<uint64_t>(tr * static_cast<double>(scale)), scale - 1);
    uint64_t cx, cy;
    int state = at.state;
    curve_.Descend(digits, continuation_levels_, &cx, &cy, &state);
    const double cell = at.side / continuation_cells_;
    u[i] = cell_.u0 + (at.x0 + (static_cast<double>(cx) + 0.5) * cell) * cell_.size;
    v[i] = cell_.v0 + (at.y0 + (static_cast<double>(cy) + 0.5) * cell) * cell_.size;
    if (curve_position != nullptr) {
      const double pos = at.pos + tr * at.span;
      curve_position[i] =
          (leaf_start_ + pos * leaf_span_) / static_cast<double>(curve_.Span(0));
    }
  }
}

}  // namespace sfc
