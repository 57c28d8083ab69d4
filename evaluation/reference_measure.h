// A reference measure for density discrepancy that shares nothing with the
// curve tree (docs/ALGORITHM.md, "Evaluation protocol"): the mass of delta dA on
// each cell of a uniform parameter grid by a graded tensor Gauss-Legendre
// rule. Each cell's axis is mapped by the polynomial q(s) = 10 s^3 - 15 s^4 +
// 6 s^5, whose derivative 30 s^2 (1-s)^2 vanishes to second order at both
// ends, so an area element that
// blows up like |t|^(-2/3) on a cell edge (the superellipsoid's singular
// lines, paper Sect. 5.3, all on edges of a 2^k grid) becomes bounded and
// the rule converges. Only the surface's jet and the density are shared
// with the sampler.
//
// Thread-safety: pure function.
#ifndef SFCSAMPLER_EVALUATION_REFERENCE_MEASURE_H_
#define SFCSAMPLER_EVALUATION_REFERENCE_MEASURE_H_

#include <vector>

#include "absl/status/statusor.h"
#include "core/density.h"
#include "core/surface.h"

namespace sfc {

// masses[i * grid + j] = int over [i/grid, (i+1)/grid] x [j/grid, (j+1)/grid]
// of delta dA, with `nodes` graded Gauss-Legendre nodes per axis and cell.
// Errors: INVALID_ARGUMENT where the surface, its area element away from the
// cell edges, or the density is not finite. REQUIRES: 1 <= nodes <= 16.
absl::StatusOr<std::vector<double>> GradedCellMasses(const Surface& surface, const Density& density,
                                                     int grid, int nodes);

}  // namespace sfc

#endif  // SFCSAMPLER_EVALUATION_REFERENCE_MEASURE_H_
