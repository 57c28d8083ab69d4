// Whether a request's value columns can travel as float32
// (request/stream_options.h ColumnPrecision::kFloat32) without being changed
// past rounding: a finite double beyond float32's largest finite value
// (FLT_MAX, about 3.4e38) would become +-infinity, and a surface smaller
// than float32's normal range (FLT_MIN, about 1.2e-38) would come out as
// zeros and subnormals. Such a request is refused with INVALID_ARGUMENT,
// naming the columns and what to do (float64, or scale the surface or the
// density), never sent changed. Checked in two places, both in the engine
// that the CLI, the server and Python share (engine/sampling_engine.h Start):
//   - before any sample is made, from what the surface's kind measured of
//     its values (ValueExtent: points and densities it evaluated), and
//   - as each batch leaves the cursor (Float32CheckedCursor), for the values
//     no measurement foresaw: a finite value that float32 makes infinite ends
//     the request, naming the column and the sample's index.
// u, v, the unit normal and curve_position lie in [-1, 1] and always fit.
//
// Thread-safety: functions are pure; a cursor is used by one thread at a time.
#ifndef SFCSAMPLER_ENGINE_FLOAT32_RANGE_H_
#define SFCSAMPLER_ENGINE_FLOAT32_RANGE_H_

#include <cfloat>
#include <memory>

#include "absl/status/status.h"
#include "core/density.h"
#include "core/surface.h"
#include "core/types/sample_batch.h"
#include "engine/batch_cursor.h"

namespace sfc {

// What a kind of surface measured of its samples' values before sampling
// (at points of its own choosing, e.g. core/curve_tree.h's tolerance grid):
// values that occur, so a refusal made from them is never wrong. Empty
// (measured false) when the kind measured nothing; the cursor check remains.
struct ValueExtent {
  bool measured = false;
  // The box of the surface points it evaluated.
  Vec3 lo{0, 0, 0}, hi{0, 0, 0};
  // The largest density delta it evaluated, with its parameter point.
  double max_density = 0;
  double max_density_u = 0, max_density_v = 0;
};

// The box's diagonal below which a surface's float32 coordinates near the
// origin are subnormal: fewer than 2^23 float32 steps (FLT_TRUE_MIN apart)
// across it, where float32 promises 2^23 steps per binade; a surface of
// diagonal 1e-50 comes out as all zeros.
inline constexpr double kFloat32SmallestSize = FLT_MIN;

// The extent of `surface`'s points on core/curve_tree.h's tolerance grid
// (WidenByGridPoints, non-finite points skipped) and of the density there
// (points whose density cannot be evaluated are skipped: the tree build
// reports them). For formula surfaces, whose trees keep no surface.
ValueExtent MeasureValues(const Surface& surface, const Density& density);

// OK when every value column of `fields` fits float32 as far as `extent`
// knows; else INVALID_ARGUMENT naming the columns (x, y, z by the box,
// density by max_density) and what to do.
absl::Status CheckFloat32Extent(const ValueExtent& extent, const SampleFields& fields);

// OK when every value of samples [begin, batch.size()) of `batch`, in the
// columns `fields` sends, rounds to a finite float (non-finite doubles stay
// as they are); else INVALID_ARGUMENT naming the first such column and the
// sample's index. Columns the client did not ask for are not checked.
absl::Status CheckFloat32Batch(const SampleBatch& batch, size_t begin,
                               const SampleFields& fields);

// `cursor`, with each batch it appends checked by CheckFloat32Batch.
std::unique_ptr<BatchCursor> Float32CheckedCursor(std::unique_ptr<BatchCursor> cursor,
                                                  const SampleFields& fields);

}  // namespace sfc

#endif  // SFCSAMPLER_ENGINE_FLOAT32_RANGE_H_
