// Reference point sets for the evaluation protocol (paper Sects. 2, 4, 5.1),
// written from their definitions. Thread-safety: pure functions.
#ifndef SFCSAMPLER_EVALUATION_REFERENCE_SETS_H_
#define SFCSAMPLER_EVALUATION_REFERENCE_SETS_H_

#include <cstdint>
#include <vector>

#include "evaluation/discrepancy.h"
#include "core/types/vec3.h"

namespace sfc {

// Unit square.
std::vector<Point2> RandomSquare(uint64_t n, uint64_t seed);
// 2D jittered: N equal-area strata (rows of floor(sqrt N), row lengths
// differing by at most one), one uniform point in each.
std::vector<Point2> JitteredSquare(uint64_t n, uint64_t seed);
// The 2D Sobol sequence (first n points): x = base-2 radical inverse, y from
// the direction numbers of the primitive polynomial x + 1. A (0,2)-sequence.
std::vector<Point2> SobolSquare(uint64_t n);
// Halton in bases 2 and 3.
std::vector<Point2> HaltonSquare(uint64_t n);
// Hammersley: (i/n, base-2 radical inverse of i).
std::vector<Point2> HammersleySquare(uint64_t n);

// Unit sphere.
std::vector<Vec3> RandomSphere(uint64_t n, uint64_t seed);
// Hammersley on the sphere (Wong, Luk, Heng 1997): z = 2 t - 1 with t the
// base-2 radical inverse of k, phi = 2 pi (k + 1/2) / n.
std::vector<Vec3> HammersleySphere(uint64_t n);
// Spherical Fibonacci: z = 1 - (2k + 1)/n, phi = 2 pi k / golden ratio.
std::vector<Vec3> FibonacciSphere(uint64_t n);

// Base-2 radical inverse of k in [0,1).
double RadicalInverse2(uint64_t k);

}  // namespace sfc

#endif  // SFCSAMPLER_EVALUATION_REFERENCE_SETS_H_
