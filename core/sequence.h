// One-dimensional sequences q_k in [0,1) that are placed along the curve
// (paper Sect. 3, "Create1DPoints"; docs/ALGORITHM.md step 3).
//
// Every q_k is a pure function of (kind, count, seed, k), so any index can be
// computed alone. Thread-safety: immutable value type.
#ifndef SFCSAMPLER_CORE_SEQUENCE_H_
#define SFCSAMPLER_CORE_SEQUENCE_H_

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string_view>
#include <utility>
#include <vector>

#include "core/types/sequence_kind.h"
#include "core/vector_math.h"

namespace sfc {

// The nested scrambles of sobol and progressive, computed once per sequence
// (core/sequence_internal.h).
struct ScrambleTables;

class Sequence {
 public:
  // REQUIRES: 1 <= count <= MaxSequenceCount(kind); not kBlue (its values
  // come from a relaxation: FromTable).
  Sequence(SequenceKind kind, uint64_t count, uint64_t seed)
      : kind_(kind), count_(count), seed_(seed) {
    if (kind == SequenceKind::kSobol || kind == SequenceKind::kProgressive) {
      scrambles_ = MakeScrambles(kind, seed);
    }
  }

  // A kBlue sequence whose q_k is (*q)[k], shared: the result of
  // RelaxBlueNoise (core/blue_relaxation.h), or any mass coordinates to
  // place. REQUIRES: q non-empty, non-decreasing, in [0, 1].
  static Sequence FromTable(std::shared_ptr<const std::vector<double>> q, uint64_t seed) {
    Sequence s(SequenceKind::kBlue, q->size(), seed);
    s.table_ = std::move(q);
    return s;
  }

  SequenceKind kind() const { return kind_; }
  uint64_t count() const { return count_; }
  uint64_t seed() const { return seed_; }

  // True when q_k is non-decreasing in k, so index order is curve order and an
  // index range is a contiguous stretch of the curve.
  bool monotone() const { return SequenceIsMonotone(kind_); }

  // q_k in [0,1]. REQUIRES: k < count() (the radical-inverse kinds accept any
  // k < 2^32: they do not depend on count). For a window, (q_k - lo)/(hi - lo).
  double At(uint64_t k) const {
    const double q = Raw(k);
    return windowed_ ? (q - lo_) / (hi_ - lo_) : q;
  }

  // out[i] = At(k0 + i) for i < n, bit for bit, in one call: the loop runs
  // per kind, so a batch pays the dispatch once. REQUIRES: k0 + n <= count().
  void AtMany(uint64_t k0, size_t n, double* out) const;

  // The part of the sequence with lo <= q_k < hi (hi = 1 also takes q_k = 1),
  // rescaled to [0, 1): the samples of one piece of a surface made of pieces
  // that share one equalisation (a CAD model's faces, cad/model_sampler.h).
  // Windows [a, b) and [b, c) made with the same double b split the samples
  // exactly. REQUIRES: 0 <= lo < hi <= 1.
  Sequence Window(double lo, double hi) const {
    Sequence w = *this;
    w.windowed_ = true, w.lo_ = lo, w.hi_ = hi;
    return w;
  }
  // True when q_k lies in the window (always without one).
  bool InWindow(uint64_t k) const {
    if (!windowed_) return true;
    const double q = Raw(k);
    return q >= lo_ && (q < hi_ || (hi_ == 1 && q == 1));
  }
  bool windowed() const { return windowed_; }

  // Two-dimensional kinds (SequenceIsTwoDimensional, sobol): the second
  // coordinate of point k in [0, 1); At(k) is its first. Sobol point k is the
  // Owen-scrambled (radical inverse of k, Sobol's second dimension of k): a
  // pure function of (seed, k), not of count. REQUIRES: k < 2^32.
  double Second(uint64_t k) const;
  // a[i] = At(k), b[i] = Second(k) of k = ks[i] (k0 + i when ks is null), i <
  // n, bit for bit, in one call (the two coordinates share k's hashing;
  // eight points at a time on the AVX-512F vector path). REQUIRES: kSobol,
  // math::Runs(path).
  void PointsMany(const uint32_t* ks, uint64_t k0, size_t n, double* a, double* b,
                  math::VectorPath path = math::BestVectorPath()) const;
  bool two_dimensional() const { return SequenceIsTwoDimensional(kind_); }

 private:
  double Raw(uint64_t k) const;  // q_k
  static std::shared_ptr<const ScrambleTables> MakeScrambles(SequenceKind kind, uint64_t seed);

  SequenceKind kind_;
  uint64_t count_;
  uint64_t seed_;
  std::shared_ptr<const std::vector<double>> table_;  // kBlue's q_k
  bool windowed_ = false;
  double lo_ = 0, hi_ = 1;
  // The scrambles of sobol and progressive: shared by copies and windows.
  std::shared_ptr<const ScrambleTables> scrambles_;
};

// The first k in [0, count) for which reached(k) holds, for a predicate that
// is false and then true along k (such as q_k S_M >= m for a monotone
// sequence); count if none. O(log count) calls.
template <typename Reached>
uint64_t FirstIndexWhere(uint64_t count, const Reached& reached) {
  uint64_t lo = 0, hi = count;
  while (lo < hi) {
    const uint64_t mid = lo + (hi - lo) / 2;
    if (reached(mid)) {
      hi = mid;
    } else {
      lo = mid + 1;
    }
  }
  return lo;
}

// The indices [begin, end) in curve order, for sequences that are not
// monotone in k: sorted by `mass_coordinate(k)` (q_k S_M), ties by index;
// only those `keep(k)` accepts (a window's). Holds 16 bytes an index while it
// sorts.
template <typename MassCoordinate, typename Keep>
std::vector<uint64_t> IndicesInCurveOrder(uint64_t begin, uint64_t end,
                                          const MassCoordinate& mass_coordinate, const Keep& keep) {
  std::vector<std::pair<double, uint64_t>> keyed;
  keyed.reserve(end - begin);
  for (uint64_t k = begin; k < end; ++k) {
    if (keep(k)) keyed.emplace_back(mass_coordinate(k), k);
  }
  std::sort(keyed.begin(), keyed.end());
  std::vector<uint64_t> order;
  order.reserve(keyed.size());
  for (const auto& [m, k] : keyed) order.push_back(k);
  return order;
}

}  // namespace sfc

#endif  // SFCSAMPLER_CORE_SEQUENCE_H_
