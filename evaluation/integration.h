// Issue 36's integration table for `sfcsampler eval` (the quality section
// "integration"): the sample means of smooth functions against exact values
// this file computes itself from the surfaces' formulas, never from the
// sampler, for every mode that integrates (jittered, sobol, progressive):
//  - f = x^2 + 0.3 y z + exp(z) on the unit sphere (closed form), the torus
//    R = 2, r = 1 (a 512 x 512 periodic trapezoid rule, spectrally exact),
//    the default superellipsoid e = 1/3 (Gauss-Legendre on each quarter of
//    both angles after a substitution that smooths the singular lines) and a
//    STEP sphere when one is given (its points scaled to the unit sphere);
//  - g = x^2 + 0.3 y z + z on an icosphere of 5120 flat triangles that this
//    file builds and writes as OBJ (the edge-midpoint rule is exact for a
//    quadratic on a flat triangle).
// Mean |error| over the seeds at each N with its standard error over the
// seeds (the spread of one seed's error over sqrt(seeds)), the least-squares
// slope of its log against log N, and the points and time to reach 1e-4 and
// 1e-5 read off the fitted lines (extrapolated past the largest N, marked so).
//
// Thread-safety: reentrant.
#ifndef SFCSAMPLER_EVALUATION_INTEGRATION_H_
#define SFCSAMPLER_EVALUATION_INTEGRATION_H_

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "evaluation/quality.h"

namespace sfc {

struct IntegrationOptions {
  bool full = false;  // N = 2^10..2^16 (else 2^10..2^14)
  std::vector<uint64_t> seeds = {1, 2, 3};
  std::string step_sphere;  // model spec of a sphere centred at 0; empty: skipped
  std::string work_dir;     // where the icosphere's OBJ is written (and removed)
  std::function<void(const std::string&)> progress;
};

// The tables (markdown) and the checks, appended to `checks`.
absl::StatusOr<std::string> IntegrationTables(const IntegrationOptions& options,
                                              const QualitySource& source,
                                              std::vector<QualityCheck>* checks);

// The exact means (of f, resp. g on the icosphere's flat triangles).
double SphereMeanOfF();
double TorusMeanOfF(double big_r, double small_r);
double SuperellipsoidMeanOfF(double e);

}  // namespace sfc

#endif  // SFCSAMPLER_EVALUATION_INTEGRATION_H_
