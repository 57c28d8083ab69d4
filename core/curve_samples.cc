#include "core/curve_samples.h"

#include <algorithm>

#include "absl/strings/str_format.h"

namespace sfc {

SampleRows SampleRows::From(size_t offset) const {
  auto at = [offset](auto* column) { return column == nullptr ? nullptr : column + offset; };
  return {index + offset, at(u),  at(v),  at(x),       at(y),
          at(z),          at(nx), at(ny), at(nz),      at(density),
          at(curve_position), at(triangle)};
}

absl::Status SampleFiller::FillAddressed(size_t, const CurveAddress*, const SampleRows&) {
  return absl::UnimplementedError("this kind of surface places no two-dimensional sequence");
}

absl::Status CurveSamples::AcceptsSequence(const Sequence& sequence) const {
  if (!sequence.two_dimensional()) return absl::OkStatus();
  return absl::InvalidArgumentError(
      absl::StrFormat("the %s sequence is not available for this kind of surface",
                      SequenceName(sequence.kind())));
}

void CurveSamples::AddressesOf(const uint32_t* ks, uint64_t k0, size_t n, CurveAddress* out) const {
  // A batch's points first, then one call of the kind's warp for them.
  constexpr size_t kBatch = 256;
  double a[kBatch], b[kBatch];
  for (size_t i0 = 0; i0 < n; i0 += kBatch) {
    const size_t m = std::min(kBatch, n - i0);
    sequence_.PointsMany(ks != nullptr ? ks + i0 : nullptr, k0 + i0, m, a, b);
    WarpMany(m, a, b, out + i0);
    for (size_t i = 0; i < m; ++i) {
      out[i0 + i].index = static_cast<uint32_t>(ks != nullptr ? ks[i0 + i] : k0 + i0 + i);
    }
  }
}

uint64_t CurveSamples::FirstIndexAtOrAbove(double m) const {
  return FirstIndexWhere(sequence_.count(), [&](uint64_t k) { return MassCoordinate(k) >= m; });
}

void CurveSamples::AddMassRange(double m0, double m1, bool through_end, uint64_t begin,
                                uint64_t end, std::vector<IndexSegment>* segments) const {
  const uint64_t kb = FirstIndexAtOrAbove(m0);
  const uint64_t ke = through_end ? sequence_.count() : FirstIndexAtOrAbove(m1);
  const uint64_t lo = std::max(kb, begin), hi = std::min(ke, end);
  if (lo >= hi) return;
  if (!segments->empty() && segments->back().end == lo) {
    segments->back().end = hi;
  } else {
    segments->push_back({lo, hi});
  }
}

}  // namespace sfc
