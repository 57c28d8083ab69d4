// The vector paths of the superellipsoid's batch points
// (core/builtin_surfaces.cc, Superellipsoid::Points): one source,
// core/superellipsoid_lanes.h, built for AVX-512F in
// core/superellipsoid_avx512.cc (called only on the kAvx512 vector path,
// math::BestVectorPath()) and for AVX2 in core/superellipsoid_avx2.cc (only
// on the kAvx2 path). Each gives the bits of the scalar reference,
// Superellipsoid::Point, which the other paths run. Not for use outside the
// superellipsoid and its tests.
#ifndef SFCSAMPLER_CORE_SUPERELLIPSOID_INTERNAL_H_
#define SFCSAMPLER_CORE_SUPERELLIPSOID_INTERNAL_H_

#include <cstddef>

namespace sfc::superellipsoid_internal {

// The superellipsoid's shape: exponent e > 0, and whether the angles follow
// the power-law reparameterisation (paper Sect. 5.3).
struct Shape {
  double e;
  bool reparam;
};

// Superellipsoid::Point(u[i], v[i]) into x[i], y[i], z[i], bit for bit, for
// the points from 0 on in whole blocks of kBlock (vectors of 8 lanes on
// AVX-512F, 4 on AVX2) while every parameter of a block lies in [0, 1] (the
// sampler's domain; elsewhere the scalar reference). Returns how many points
// it placed: a multiple of kBlock, at most n.
inline constexpr size_t kBlock = 64;
size_t PointsAvx512(Shape shape, const double* u, const double* v, size_t n, double* x, double* y,
                    double* z);
size_t PointsAvx2(Shape shape, const double* u, const double* v, size_t n, double* x, double* y,
                  double* z);

}  // namespace sfc::superellipsoid_internal

#endif  // SFCSAMPLER_CORE_SUPERELLIPSOID_INTERNAL_H_
