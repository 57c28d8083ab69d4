#include "core/curve.h"

#include <cassert>
#include <functional>

#include "core/vector_math.h"

namespace sfc {
namespace {

// The 8 symmetries of the square, as an index: bit 0 swaps x and y, then
// bit 1 mirrors x and bit 2 mirrors y. Acting on cell (i, j) of an n x n grid.
struct Cell {
  int i, j;
  bool operator==(const Cell& o) const { return i == o.i && j == o.j; }
};

Cell Apply(int t, Cell c, int n) {
  if (t & 1) std::swap(c.i, c.j);
  if (t & 2) c.i = n - 1 - c.i;
  if (t & 4) c.j = n - 1 - c.j;
  return c;
}

// a o b: apply b first, then a. Identified by the image of a point with a
// trivial stabiliser.
int Compose(int a, int b) {
  const Cell probe{0, 1};
  const Cell target = Apply(a, Apply(b, probe, 4), 4);
  for (int t = 0; t < 8; ++t) {
    if (Apply(t, probe, 4) == target) return t;
  }
  assert(false);
  return 0;
}

}  // namespace

// A curve is given by its base visiting order (orientation 0) and the corner
// of the unit cell where it ends; it always starts at corner (0,0). The
// orientation of every child is derived, not tabulated by hand: each child's
// sub-curve must start at the corner where the previous one ended, and end on
// a corner shared with the next child (the last at the parent's end corner).
// Among equal choices the one without a swap wins, which gives the classic
// serpentine Peano curve.
struct Curve::Definition {
  CurveType type;
  int grid;
  std::vector<Cell> order;
  Cell end_corner;
  int max_depth;
};

namespace {

std::vector<int> DeriveChildOrientations(const std::vector<Cell>& order, Cell end_corner,
                                         int grid) {
  const int w = static_cast<int>(order.size());
  std::vector<int> orient(w, -1);
  static constexpr int kPreference[8] = {0, 2, 4, 6, 1, 3, 5, 7};
  auto corner_of = [&](int child, int t, Cell base_corner) {
    const Cell local = Apply(t, base_corner, 2);
    return Cell{order[child].i + local.i, order[child].j + local.j};
  };
  auto is_corner_of = [&](Cell p, int child) {
    const int di = p.i - order[child].i, dj = p.j - order[child].j;
    return (di == 0 || di == 1) && (dj == 0 || dj == 1);
  };
  const Cell parent_end{end_corner.i * grid, end_corner.j * grid};
  std::function<bool(int, Cell)> place = [&](int c, Cell entry) {
    if (c == w) return true;
    for (int t : kPreference) {
      if (!(corner_of(c, t, Cell{0, 0}) == entry)) continue;
      const Cell exit = corner_of(c, t, end_corner);
      const bool ok = c + 1 < w ? is_corner_of(exit, c + 1) : exit == parent_end;
      if (!ok) continue;
      orient[c] = t;
      if (place(c + 1, exit)) return true;
    }
    return false;
  };
  const bool found = place(0, Cell{0, 0});
  assert(found);
  (void)found;
  return orient;
}

const Curve::Definition& DefinitionOf(CurveType type);

}  // namespace

Curve::Curve(const Definition& def)
    : type_(def.type),
      grid_(def.grid),
      arity_(def.grid * def.grid),
      max_depth_(def.max_depth) {
  const std::vector<int> orient = DeriveChildOrientations(def.order, def.end_corner, grid_);
  children_.resize(8 * arity_);
  for (int s = 0; s < 8; ++s) {
    for (int c = 0; c < arity_; ++c) {
      const Cell pos = Apply(s, def.order[c], grid_);
      children_[s * arity_ + c] = Child{static_cast<uint8_t>(pos.i), static_cast<uint8_t>(pos.j),
                                        static_cast<uint8_t>(Compose(s, orient[c]))};
    }
  }
  // Powers of w up to w^D (also covers continuation: w^L <= 2^53 < w^D).
  pow_w_.assign(max_depth_ + 1, 1);
  for (int k = 1; k <= max_depth_; ++k) pow_w_[k] = pow_w_[k - 1] * arity_;
  pow_g_.assign(2 * max_depth_ + 1, 1.0);
  for (int k = 1; k <= 2 * max_depth_; ++k) pow_g_[k] = pow_g_[k - 1] * grid_;
  continuation_levels_ = 0;
  while (pow_w_[continuation_levels_ + 1] <= (uint64_t{1} << 53)) ++continuation_levels_;
  digit_bits_ = arity_ == 4 ? 2 : 0;

  // Chunk tables: the effect of chunk_levels_ levels at once (<= 256 entries).
  chunk_levels_ = arity_ == 4 ? 4 : 2;
  const int chunk_size = static_cast<int>(pow_w_[chunk_levels_]);
  chunk_shift_ = 0;
  while ((1 << chunk_shift_) < chunk_size) ++chunk_shift_;
  chunk_side_ = static_cast<uint64_t>(pow_g_[chunk_levels_]);
  chunks_.resize(8 << chunk_shift_);
  for (int s = 0; s < 8; ++s) {
    for (int value = 0; value < chunk_size; ++value) {
      int state = s, x = 0, y = 0;
      for (int level = chunk_levels_ - 1; level >= 0; --level) {
        const int digit = static_cast<int>(value / pow_w_[level]) % arity_;
        const Child& ch = ChildOf(state, digit);
        x = x * grid_ + ch.dx;
        y = y * grid_ + ch.dy;
        state = ch.state;
      }
      chunks_[(s << chunk_shift_) + value] = ChunkEntry{
          static_cast<uint16_t>(x), static_cast<uint16_t>(y), static_cast<uint8_t>(state)};
    }
  }

  // Cells in curve order, up to 32 per side.
  table_levels_ = arity_ == 4 ? 5 : 3;
  cell_order_.resize(table_levels_ + 1);
  for (int levels = 1; levels <= table_levels_; ++levels) {
    const int cells = static_cast<int>(pow_w_[levels]);
    cell_order_[levels].resize(8 * cells);
    for (int s = 0; s < 8; ++s) {
      for (int k = 0; k < cells; ++k) {
        uint64_t x, y;
        int state = s;
        DescendByTables(k, levels, &x, &y, &state);
        cell_order_[levels][s * cells + k] =
            Child{static_cast<uint8_t>(x), static_cast<uint8_t>(y), static_cast<uint8_t>(state)};
      }
    }
  }

  constexpr int kWholes[4] = {0, 1, 6, 7};  // by swap parity + 2 mirror parity
  for (int a = 0; a < 8; ++a) {
    for (int w = 0; w < 4; ++w) {
      batch_masks_.compose[a >> 2] |= uint64_t(Compose(a, kWholes[w])) << (4 * (4 * (a & 3) + w));
    }
  }
  // Bit-parallel decoding needs a 2 x 2 curve whose children's orientations
  // are only swaps and mirrors of both axes (true of Hilbert).
  bit_parallel_ = arity_ == 4;
  for (int d = 0; d < arity_ && bit_parallel_; ++d) {
    const int o = orient[d];
    bit_parallel_ = o == 0 || o == 1 || o == 6 || o == 7;
    const auto mask = [](bool on) { return on ? ~uint64_t{0} : uint64_t{0}; };
    batch_masks_.x[d] = mask(def.order[d].i == 1);
    batch_masks_.y[d] = mask(def.order[d].j == 1);
    batch_masks_.swap[d] = mask(o & 1);
    batch_masks_.mirror[d] = mask(o & 6);
  }
}

void Curve::DescendMany(const uint64_t* digits, int levels, size_t n, uint64_t* states, uint64_t* x,
                        uint64_t* y) const {
  if (bit_parallel_ && levels <= 32) {
    const math::VectorPath path = math::BestVectorPath();
    if (path == math::VectorPath::kAvx512) {
      hilbert_batch::DescendAvx512(batch_masks_, digits, levels, n, states, x, y);
    } else if (path == math::VectorPath::kAvx2) {
      hilbert_batch::DescendAvx2(batch_masks_, digits, levels, n, states, x, y);
    } else {
      hilbert_batch::Descend(batch_masks_, digits, levels, n, states, x, y);
    }
    return;
  }
  for (size_t i = 0; i < n; ++i) {
    int state = static_cast<int>(states[i]);
    DescendByTables(digits[i], levels, &x[i], &y[i], &state);
    states[i] = static_cast<uint64_t>(state);
  }
}

int Curve::DepthOfSpan(uint64_t span) const {
  if (digit_bits_) return max_depth_ - __builtin_ctzll(span) / digit_bits_;
  int k = 0;
  while (pow_w_[k] < span) ++k;
  return max_depth_ - k;
}

namespace {

const Curve::Definition& DefinitionOf(CurveType type) {
  static const Curve::Definition kHilbert{
      CurveType::kHilbert, 2, {{0, 0}, {0, 1}, {1, 1}, {1, 0}}, {1, 0}, 31};
  // A 3x3 meander (Wunderlich's family): up the left column, along the top,
  // down into the centre and out along the bottom. It has no axis of symmetry.
  static const Curve::Definition kHilbert2{
      CurveType::kHilbert2,
      3,
      {{0, 0}, {0, 1}, {0, 2}, {1, 2}, {2, 2}, {2, 1}, {1, 1}, {1, 0}, {2, 0}},
      {1, 0},
      20};
  static const Curve::Definition kPeano{
      CurveType::kPeano,
      3,
      {{0, 0}, {0, 1}, {0, 2}, {1, 2}, {1, 1}, {1, 0}, {2, 0}, {2, 1}, {2, 2}},
      {1, 1},
      20};
  switch (type) {
    case CurveType::kHilbert:
      return kHilbert;
    case CurveType::kHilbert2:
      return kHilbert2;
    case CurveType::kPeano:
      return kPeano;
  }
  return kHilbert;
}

}  // namespace

const Curve& Curve::Get(CurveType type) {
  static const Curve* const kCurves[3] = {new Curve(DefinitionOf(CurveType::kHilbert)),
                                          new Curve(DefinitionOf(CurveType::kHilbert2)),
                                          new Curve(DefinitionOf(CurveType::kPeano))};
  return *kCurves[static_cast<int>(type)];
}


}  // namespace sfc
