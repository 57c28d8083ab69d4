// What a SampleCursor (core/sample_cursor.h) walks: the samples of one
// sequence along one curve with total mass S_M (paper Fig. 1 line 8;
// docs/ALGORITHM.md step 4). Sample k has mass coordinate q_k S_M; the curve
// kind says which index ranges a region may hold and where each sample lies.
//
// Two kinds: core's Sampler (core/sampler.h: a CurveTree over a parametric
// surface) and the mesh sampler (mesh/mesh_sampler.h). The cursor does the rest
// once for both: the range check, the sort of non-monotone sequences, batch
// growth and truncation, the region's filtering and the thread split.
//
// Thread-safety: a CurveSamples is immutable and thread-safe; a SampleFiller
// is used by one thread at a time.
#ifndef SFCSAMPLER_CORE_CURVE_SAMPLES_H_
#define SFCSAMPLER_CORE_CURVE_SAMPLES_H_

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "absl/status/status.h"
#include "core/sequence.h"
#include "core/types/region.h"
#include "core/types/sample_batch.h"
#include "core/vector_math.h"

namespace sfc {

// The curve_position column's value at `along` of `total` units of the curve
// (the tree's curve indices, a mesh's triangle ranks, a model's pieces):
// along / total, kept in [0, 1) as the column promises (the quotient rounds
// up to 1 when along is within rounding of total).
inline double CurvePosition(double along, double total) {
  return std::min(along / total, math::kBelowOne);
}

// A batch's columns from one row on; null for the columns not asked for.
struct SampleRows {
  uint64_t* index;
  double *u, *v, *x, *y, *z, *nx, *ny, *nz, *density, *curve_position;
  uint32_t* triangle;
  SampleRows From(size_t offset) const;
};

// Sample indices [begin, end).
struct IndexSegment {
  uint64_t begin, end;
};

// A sample of a two-dimensional sequence (sobol) by its place on the curve:
// the kind's leaf and the digits of the leaf's own curve below it that the
// sample's warped point falls in. Addresses in this order are curve order;
// the filler places a sample from its address alone.
struct CurveAddress {
  uint64_t digits;
  uint32_t leaf;
  uint32_t index;  // the sample's k (< MaxSequenceCount(kSobol) = 2^32)
  // By leaf, then digits (below 2^52), then index: one 128-bit comparison.
  unsigned __int128 Key() const {
    return static_cast<unsigned __int128>(uint64_t{leaf} << 20 | digits >> 32) << 64 |
           (digits << 32 | index);
  }
  bool operator<(const CurveAddress& o) const { return Key() < o.Key(); }
};

// Places samples into rows, for one thread.
class SampleFiller {
 public:
  virtual ~SampleFiller() = default;
  // On entry out.index[i] holds sample k and out.x[i] its mass coordinate
  // q_k S_M, i < n, not decreasing in i. Writes u, v, x, y, z (and triangle,
  // when asked for) of every row, and the other asked columns at least of the
  // rows whose point lies in the filler's region (the cursor drops the rest
  // by Region::Contains(u, v, {x, y, z})). Errors: INVALID_ARGUMENT when the
  // surface or density is not usable at a sample.
  virtual absl::Status Fill(size_t n, const SampleRows& out) = 0;
  // The same for a two-dimensional sequence: row i is the sample at `at[i]`
  // (out.index[i] holds its k; out.x[i] is not a mass coordinate). The
  // default is UNIMPLEMENTED, for kinds without a warp.
  virtual absl::Status FillAddressed(size_t n, const CurveAddress* at, const SampleRows& out);
};

class CurveSamples {
 public:
  CurveSamples(Sequence sequence, double total_mass)
      : sequence_(sequence), total_mass_(total_mass) {}
  virtual ~CurveSamples() = default;

  const Sequence& sequence() const { return sequence_; }
  double total_mass() const { return total_mass_; }
  // q_k S_M: sample k's mass coordinate along the curve.
  double MassCoordinate(uint64_t k) const { return sequence_.At(k) * total_mass_; }
  // First k in [0, count) whose mass coordinate is >= m, for monotone
  // sequences; count if none.
  uint64_t FirstIndexAtOrAbove(double m) const;

  // OK when the kind can select by `region` (checked before
  // Region::Validate); INVALID_ARGUMENT with the reason otherwise.
  virtual absl::Status AcceptsRegion(const Region& region) const = 0;
  // Appends to `segments`, in curve order, index segments inside [begin, end)
  // that hold every sample of [begin, end) that may lie in `region` (a box or
  // rectangle, not kAll); they may hold more. Monotone sequences only.
  virtual absl::Status PlanRegion(const Region& region, uint64_t begin, uint64_t end,
                                  std::vector<IndexSegment>* segments) const = 0;
  // Two-dimensional sequences (Sequence::two_dimensional): the addresses of
  // samples ks[i] (k0 + i when ks is null), i < n, into out[i]: each
  // sample's point of the unit square (Sequence::At, Second) through the
  // kind's warp (WarpMany, a batch at a time), by which the cursor sorts the
  // whole set and the filler places it. A pure function of each k.
  void AddressesOf(const uint32_t* ks, uint64_t k0, size_t n, CurveAddress* out) const;
  // Two-dimensional sequences: every address's leaf is below this (the
  // cursor's sort buckets by it; a bound too small would lose the order, so
  // every address WarpMany gives must hold it).
  virtual uint32_t AddressLeafBound() const = 0;
  // OK when the kind can place `sequence`'s samples; INVALID_ARGUMENT with
  // the reason otherwise (a kind without a warp for two-dimensional ones).
  virtual absl::Status AcceptsSequence(const Sequence& sequence) const;
  // Whether the filler writes SampleRows::triangle.
  virtual bool has_triangles() const { return false; }
  // A filler of the columns `fields` asks for, for samples tested against
  // `region`.
  virtual std::unique_ptr<SampleFiller> NewFiller(const Region& region,
                                                  const SampleFields& fields) const = 0;

 protected:
  // Appends the indices in [begin, end) whose mass coordinates lie in
  // [m0, m1) (in [m0, S_M] when `through_end`: q_k S_M may round up to S_M)
  // to `segments`, joined to the last one when they meet it.
  void AddMassRange(double m0, double m1, bool through_end, uint64_t begin, uint64_t end,
                    std::vector<IndexSegment>* segments) const;
  // The addresses (index 0) of the points (a[i], b[i]) of the unit square,
  // i < n, through the kind's warp, into out[i]; each a pure function of its
  // point (a batch lets a kind overlap the points' descents). Kinds without
  // a warp are refused by AcceptsSequence before.
  virtual void WarpMany(size_t n, const double* a, const double* b, CurveAddress* out) const {}

 private:
  Sequence sequence_;
  double total_mass_;
};

}  // namespace sfc

#endif  // SFCSAMPLER_CORE_CURVE_SAMPLES_H_
