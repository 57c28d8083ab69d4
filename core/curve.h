// Space-filling curves on the unit square, behind one table-driven
// abstraction (paper Sect. 3 and Fig. 3; docs/ALGORITHM.md "Curves").
//
// A curve of grid g subdivides a cell into w = g*g children visited in a fixed
// order. Each cell carries an orientation ("state"), one of the 8 symmetries of
// the square; a child's position and state follow from its parent's state by
// table look-up, which is the paper's GenerateChildren "permutation".
//
// Curve indices are 64-bit: the curve at the deepest level D has w^D vertices
// (Hilbert: D = 31, 4^31 = 2^62; 3x3 curves: D = 20, 9^20 < 2^64). A cell at
// depth d covers the index range [prefix * w^(D-d), (prefix+1) * w^(D-d)).
//
// Thread-safety: Curve objects are immutable singletons; all methods are
// thread-safe.
#ifndef SFCSAMPLER_CORE_CURVE_H_
#define SFCSAMPLER_CORE_CURVE_H_

#include <array>
#include <cstdint>
#include <optional>
#include <string_view>
#include <utility>
#include <vector>

#include "core/hilbert_batch.h"
#include "core/types/tree_options.h"

namespace sfc {


class Curve {
 public:
  // The orientation of the root cell.
  static constexpr int kRootState = 0;

  static const Curve& Get(CurveType type);

  Curve(const Curve&) = delete;
  Curve& operator=(const Curve&) = delete;

  CurveType type() const { return type_; }
  int grid() const { return grid_; }        // g, cells per side per subdivision
  int arity() const { return arity_; }      // w = g*g
  int max_depth() const { return max_depth_; }  // D
  // w^(D - depth): the number of deepest-level indices a cell at `depth` covers.
  uint64_t Span(int depth) const { return pow_w_[max_depth_ - depth]; }
  // The depth-`depth` cell prefix of curve index `index`: index / Span(depth).
  uint64_t Prefix(uint64_t index, int depth) const {
    return digit_bits_ ? index >> (digit_bits_ * (max_depth_ - depth)) : index / Span(depth);
  }
  // Inverse of Span(). REQUIRES: span == Span(d) for some d in [0, D].
  int DepthOfSpan(uint64_t span) const;
  // w^k and g^k. REQUIRES: 0 <= k <= D (g^k up to 2 D).
  uint64_t PowW(int k) const { return pow_w_[k]; }
  double PowG(int k) const { return pow_g_[k]; }

  // Levels of analytic continuation inside a leaf: L such that w^L <= 2^53,
  // i.e. every bit of a double fraction in [0,1) is used (Hilbert 26, 3x3 16).
  int continuation_levels() const { return continuation_levels_; }

  struct Child {
    uint8_t dx, dy;  // offset in the parent's g x g grid
    uint8_t state;   // the child's orientation
  };
  // Child `c` (0 <= c < w, in curve order) of a cell with orientation `state`.
  const Child& ChildOf(int state, int c) const { return children_[state * arity_ + c]; }

  // The most levels CellsInOrder gives: up to 32 cells per side (Hilbert 5,
  // the 3x3 curves 3).
  int table_levels() const { return table_levels_; }
  // The w^levels cells `levels` below a cell with orientation `state`, in
  // curve order: each one's position in units of g^-levels of that cell and
  // its orientation. REQUIRES: 1 <= levels <= table_levels().
  const Child* CellsInOrder(int state, int levels) const {
    return cell_order_[levels].data() + state * pow_w_[levels];
  }

  // Follows `levels` base-w digits of `digits` (most significant first) down
  // from a cell with orientation `*state`. On return (*x, *y) is the reached
  // cell's position in units of g^-levels of the start cell, and *state its
  // orientation. REQUIRES: levels <= D + continuation_levels(), digits < w^levels
  // when levels <= D. Inline: the sampler's innermost step. The Hilbert curve
  // is decoded bit-parallel (up to 32 levels), the 3x3 curves by tables;
  // both give DescendByTables' result.
  void Descend(uint64_t digits, int levels, uint64_t* x, uint64_t* y, int* state) const {
    if (bit_parallel_ && levels <= 32) {
      DescendBitParallel(digits, levels, x, y, state);
    } else {
      DescendByTables(digits, levels, x, y, state);
    }
  }

  // Descend for n digit strings of `levels` levels each: states[i] is the
  // start orientation of string i on entry and its end orientation on return.
  // The Hilbert curve's strings are decoded as a batch, vectorised where the
  // vector path of core/vector_math.h is AVX-512F or AVX2, with Descend's
  // bits.
  void DescendMany(const uint64_t* digits, int levels, size_t n, uint64_t* states, uint64_t* x,
                   uint64_t* y) const;

  // The same by table look-ups: the leading levels % chunk_levels_ digits
  // one at a time, the rest a chunk per look-up. The reference for Descend.
  void DescendByTables(uint64_t digits, int levels, uint64_t* x, uint64_t* y, int* state) const {
    uint64_t px = 0, py = 0;
    int s = *state;
    int remaining = levels;
    for (int head = levels % chunk_levels_; head > 0; --head) {
      --remaining;
      const uint64_t digit = digit_bits_ ? (digits >> (remaining * digit_bits_)) & (arity_ - 1)
                                         : (digits / pow_w_[remaining]) % arity_;
      const Child& ch = children_[s * arity_ + digit];
      px = px * grid_ + ch.dx;
      py = py * grid_ + ch.dy;
      s = ch.state;
    }
    const uint64_t chunk_mask = pow_w_[chunk_levels_] - 1;
    while (remaining > 0) {
      remaining -= chunk_levels_;
      const uint64_t chunk = digit_bits_ ? (digits >> (remaining * digit_bits_)) & chunk_mask
                                         : (digits / pow_w_[remaining]) % pow_w_[chunk_levels_];
      const ChunkEntry& e = chunks_[(static_cast<uint64_t>(s) << chunk_shift_) + chunk];
      px = px * chunk_side_ + e.x;
      py = py * chunk_side_ + e.y;
      s = e.state;
    }
    *x = px;
    *y = py;
    *state = s;
  }

  // How a curve type is specified (see curve.cc); for the implementation.
  struct Definition;

 private:
  explicit Curve(const Definition& def);

  struct ChunkEntry {
    uint16_t x, y;
    uint8_t state;
  };

  // Hilbert, one string: hilbert_batch::Descend (bit-parallel decoding).
  void DescendBitParallel(uint64_t digits, int levels, uint64_t* x, uint64_t* y, int* state) const {
    uint64_t s = static_cast<uint64_t>(*state);
    hilbert_batch::Descend(batch_masks_, &digits, levels, 1, &s, x, y);
    *state = static_cast<int>(s);
  }

  CurveType type_;
  int grid_, arity_, max_depth_, continuation_levels_;
  int chunk_levels_;  // levels resolved per look-up in Descend
  int chunk_shift_;   // log2 of the chunk table's row length (rows padded to a power of two)
  uint64_t chunk_side_;  // g^chunk_levels_
  int digit_bits_;    // log2(w) when w is a power of two, else 0
  std::vector<uint64_t> pow_w_;
  std::vector<double> pow_g_;
  std::vector<Child> children_;       // [state][child]
  std::vector<ChunkEntry> chunks_;    // [state][chunk value]
  int table_levels_;
  std::vector<std::vector<Child>> cell_order_;  // [levels][state][cell]
  // Bit-parallel Hilbert decoding (DescendBitParallel, DescendMany) and its
  // constants.
  bool bit_parallel_ = false;
  hilbert_batch::Masks batch_masks_{};
};

}  // namespace sfc

#endif  // SFCSAMPLER_CORE_CURVE_H_
