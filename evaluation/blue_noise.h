// Blue-noise figures (issue 19): the minimum and mean nearest-neighbour
// distance of a point set, each divided by the spacing of a hexagonal
// packing of as many points on the same area, and the reference sets they
// are compared with. Thread-safety: pure functions.
#ifndef SFCSAMPLER_EVALUATION_BLUE_NOISE_H_
#define SFCSAMPLER_EVALUATION_BLUE_NOISE_H_

#include <cstdint>
#include <string>
#include <vector>

#include "core/types/vec3.h"
#include "evaluation/discrepancy.h"

namespace sfc {

struct NearestNeighbour {
  double min = 0, mean = 0;  // relative to the hexagonal spacing
};

// Unit square, Euclidean distance (no wrap-around); hexagonal spacing
// sqrt(2 / (sqrt(3) N)).
NearestNeighbour PlaneNearestNeighbour(const std::vector<Point2>& points);
// Unit sphere, chord distance; hexagonal spacing sqrt(8 pi / (sqrt(3) N)).
NearestNeighbour SphereNearestNeighbour(const std::vector<Vec3>& points);

// The radially averaged power spectrum of points in the unit square (taken
// as periodic): P(f) = mean over the integer wave vectors k with
// f - 1/2 <= |k| < f + 1/2 of |sum_j exp(-2 pi i k.x_j)|^2 / N, for
// f = 1 .. max_frequency (out[f - 1]). White noise has P = 1; blue noise is
// low at low f; a stratified set peaks near its strata's frequency
// (sqrt(N) for N strata of a square). Cost O(N max_frequency^2).
std::vector<double> RadialPowerSpectrum(const std::vector<Point2>& points, int max_frequency);

// A picture of a plane set and its spectrum side by side, as SVG: the points
// in the unit square, and P(f) against f / sqrt(N) with P = 1 dashed.
std::string PointsAndSpectrumSvg(const std::string& title, const std::vector<Point2>& points,
                                 const std::vector<double>& spectrum);

// The 2D Sobol points with Owen scrambling (nested uniform, Burley 2020's
// hash on the bit-reversed coordinate), one independent scramble per axis.
std::vector<Point2> ScrambledSobolSquare(uint64_t n, uint64_t seed);
// Dart throwing (random sequential addition): uniform candidates, kept when
// no kept point lies within `radius` (relative to the hexagonal spacing),
// until n points. The plane's Poisson-disk reference (scipy's
// qmc.PoissonDisk in bench/blue_noise.py is the other).
std::vector<Point2> DartThrowingSquare(uint64_t n, double radius, uint64_t seed);
std::vector<Vec3> DartThrowingSphere(uint64_t n, double radius, uint64_t seed);
// The square's points mapped to the sphere by the equal-area map
// z = 1 - 2 x, phi = 2 pi y.
std::vector<Vec3> SquareToSphere(const std::vector<Point2>& points);

}  // namespace sfc

#endif  // SFCSAMPLER_EVALUATION_BLUE_NOISE_H_
