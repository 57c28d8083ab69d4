#include "engine/float32_range.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "core/area_estimator.h"
#include "core/curve_tree.h"

namespace sfc {
namespace {

// Whether the finite double `d` rounds to an infinite float.
bool OverflowsFloat32(double d) { return std::isfinite(d) && std::isinf(static_cast<float>(d)); }

// What to do about columns that float32 cannot hold, scaling `what` (the
// surface, the density or both) being the other way.
std::string WhatToDo(bool surface, bool density) {
  return absl::StrFormat(
      "ask for precision float64, or scale the %s into float32's range and the samples back",
      surface && density ? "surface and the density" : (density ? "density" : "surface"));
}

}  // namespace

ValueExtent MeasureValues(const Surface& surface, const Density& density) {
  ValueExtent out;
  Vec3 lo{INFINITY, INFINITY, INFINITY}, hi{-INFINITY, -INFINITY, -INFINITY};
  double u = 0, v = 0;
  WidenByGridPoints(surface, &lo, &hi, &u, &v);
  if (lo.x <= hi.x) out.measured = true, out.lo = lo, out.hi = hi;
  for (int i = 0; i <= kToleranceGrid; ++i) {
    for (int j = 0; j <= kToleranceGrid; ++j) {
      const double s = static_cast<double>(i) / kToleranceGrid;
      const double t = static_cast<double>(j) / kToleranceGrid;
      const absl::StatusOr<DensityAt> d = EvaluateDensity(surface, density, s, t);
      if (!d.ok() || !(d->delta > out.max_density)) continue;
      out.measured = true;
      out.max_density = d->delta, out.max_density_u = s, out.max_density_v = t;
    }
  }
  return out;
}

absl::Status CheckFloat32Extent(const ValueExtent& extent, const SampleFields& fields) {
  if (!extent.measured) return absl::OkStatus();
  std::vector<std::string> problems;
  bool surface = false, density = false;
  if (fields.xyz) {
    std::vector<std::string> over;
    const double lo[3] = {extent.lo.x, extent.lo.y, extent.lo.z};
    const double hi[3] = {extent.hi.x, extent.hi.y, extent.hi.z};
    double largest = 0;
    for (int axis = 0; axis < 3; ++axis) {
      const double m = std::max(std::fabs(lo[axis]), std::fabs(hi[axis]));
      if (OverflowsFloat32(m)) {
        over.push_back(std::string(1, "xyz"[axis]));
        largest = std::max(largest, m);
      }
    }
    const double diagonal = Diagonal(extent.lo, extent.hi);
    if (!over.empty()) {
      problems.push_back(absl::StrFormat(
          "the %s column%s %g, beyond float32's largest finite value %g (written as infinity)",
          absl::StrJoin(over, ", "), over.size() > 1 ? "s reach" : " reaches", largest, FLT_MAX));
    } else if (diagonal > 0 && diagonal < kFloat32SmallestSize) {
      problems.push_back(absl::StrFormat(
          "the x, y, z columns span %g (the surface's bounding box diagonal), below float32's "
          "normal range %g (they would be written as zeros and subnormals)",
          diagonal, kFloat32SmallestSize));
    }
  }
  surface = !problems.empty();
  if (fields.density && OverflowsFloat32(extent.max_density)) {
    density = true;
    problems.push_back(absl::StrFormat(
        "the density column reaches %g at (u,v) = (%g, %g), beyond float32's largest finite "
        "value %g (it would be written as infinity)",
        extent.max_density, extent.max_density_u, extent.max_density_v, FLT_MAX));
  }
  if (problems.empty()) return absl::OkStatus();
  return absl::InvalidArgumentError(
      absl::StrFormat("float32 precision cannot hold this request: %s; %s",
                      absl::StrJoin(problems, "; "), WhatToDo(surface, density)));
}

absl::Status CheckFloat32Batch(const SampleBatch& batch, size_t begin,
                               const SampleFields& fields) {
  // SampleBatch::ValueColumns()'s columns, in its order: their names, and
  // whether `fields` sends them (the engine computes u, v, x, y, z always).
  static constexpr const char* kNames[] = {"u",  "v",  "x",  "y",       "z",
                                           "nx", "ny", "nz", "density", "curve_position"};
  const bool sent[] = {fields.uv,     fields.uv,     fields.xyz,     fields.xyz,
                       fields.xyz,    fields.normal, fields.normal,  fields.normal,
                       fields.density, fields.curve_position};
  const auto& columns = SampleBatch::ValueColumns();
  static_assert(std::size(kNames) == std::tuple_size_v<std::decay_t<decltype(columns)>>);
  for (size_t c = 0; c < columns.size(); ++c) {
    if (!sent[c]) continue;
    const std::vector<double>& column = batch.*columns[c];
    // The whole column without an early exit, so the test runs in vector
    // registers; the first offender is looked up only when there is one.
    bool any = false;
    for (size_t i = begin; i < column.size(); ++i) any |= OverflowsFloat32(column[i]);
    if (!any) continue;
    size_t i = begin;
    while (!OverflowsFloat32(column[i])) ++i;
    return absl::InvalidArgumentError(absl::StrFormat(
        "float32 precision cannot hold this request: the %s column's value %g at sample index %d "
        "is beyond float32's largest finite value %g (it would be written as infinity); "
        "earlier batches may have been delivered; %s",
        kNames[c], column[i], batch.index[i], FLT_MAX,
        WhatToDo(columns[c] != &SampleBatch::density, columns[c] == &SampleBatch::density)));
  }
  return absl::OkStatus();
}

namespace {

class Float32Checked final : public BatchCursor {
 public:
  Float32Checked(std::unique_ptr<BatchCursor> cursor, const SampleFields& fields)
      : cursor_(std::move(cursor)), fields_(fields) {}
  absl::StatusOr<size_t> Next(size_t max, SampleBatch* batch) override {
    const size_t begin = batch->size();
    absl::StatusOr<size_t> n = cursor_->Next(max, batch);
    if (!n.ok()) return n;
    if (absl::Status s = CheckFloat32Batch(*batch, begin, fields_); !s.ok()) return s;
    return n;
  }

 private:
  std::unique_ptr<BatchCursor> cursor_;
  const SampleFields fields_;
};

}  // namespace

std::unique_ptr<BatchCursor> Float32CheckedCursor(std::unique_ptr<BatchCursor> cursor,
                                                  const SampleFields& fields) {
  return std::make_unique<Float32Checked>(std::move(cursor), fields);
}

}  // namespace sfc
