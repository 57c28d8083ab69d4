// Sampling densities delta >= 0 on a surface (paper Sect. 3: "a non-negative
// bounded density function").
//
// Thread-safety: implementations are immutable and thread-safe.
#ifndef SFCSAMPLER_CORE_DENSITY_H_
#define SFCSAMPLER_CORE_DENSITY_H_

#include <memory>

#include "core/types/vec3.h"

namespace sfc {

class Surface;

// What a density may depend on at one surface point.
struct SurfacePoint {
  double u = 0, v = 0;            // unit-square parameters
  Vec3 p;                         // f(u, v)
  Vec3 normal;                    // valid only if the density NeedsCurvature()
  double gaussian_curvature = 0;  // likewise
  double mean_curvature = 0;      // likewise
};

class Density {
 public:
  virtual ~Density() = default;
  // True when Value() reads the normal or the curvatures (so callers evaluate
  // 2nd-order jets and the full geometry).
  virtual bool NeedsCurvature() const { return false; }
  // delta at the point. Callers reject negative or non-finite values.
  virtual double Value(const SurfacePoint& point) const = 0;
  // The unit-square side of the cells below which the tree need not follow
  // this density's steps with leaves of their own (issue 33's rough
  // refinement, core/curve_tree.cc), because the sampler keeps its samples
  // on the right side of them by other means. 0 (every density of the
  // catalogue): steps are followed down to CurveTree::kRoughFloor samples.
  virtual double StepResolution() const { return 0; }
  // True when delta is the same everywhere (MakeUniformDensity), so a part's
  // mass is its area: CAD models then share samples among their faces by
  // their exact trimmed areas, with no coarse tree to estimate them.
  virtual bool IsUniform() const { return false; }
  // True when Value is the uniform density's at every point of the closed
  // rectangle [u0,u1] x [v0,v1] (a CAD face's density on a cell its trim
  // keeps whole): the tree treats the cell as under IsUniform
  // (core/curve_tree.h). IsUniform(), the default.
  virtual bool IsUniformOn(double u0, double u1, double v0, double v1) const {
    (void)u0, (void)u1, (void)v0, (void)v1;
    return IsUniform();
  }
  // Whether UpperBound can be finite: the tree then checks that no feature
  // narrower than its probes hides mass in a leaf (docs/ALGORITHM.md,
  // "Features narrower than the probes"). False (the default, and every
  // built-in density: the uniform one hides nothing, the curvature ones
  // cannot bound themselves) skips that check.
  virtual bool Bounds() const { return false; }
  // An upper bound of delta over the patch of the parameter rectangle
  // [u0,u1] x [v0,v1] of `surface`, proven by interval arithmetic
  // (core/interval.h) for the values Value computes there; +infinity where
  // the density cannot bound itself (the default). REQUIRES: 0 <= u0 <= u1
  // <= 1, 0 <= v0 <= v1 <= 1.
  virtual double UpperBound(const Surface& surface, double u0, double u1, double v0,
                            double v1) const;
};

// delta = 1.
std::unique_ptr<Density> MakeUniformDensity();

// delta = max(|K|, floor): proportional to |Gaussian curvature| (paper
// Sect. 5.2); the floor keeps flat regions sampled. REQUIRES: floor >= 0.
std::unique_ptr<Density> MakeGaussianCurvatureDensity(double floor);

// delta = max(|H|, floor), H the mean curvature. REQUIRES: floor >= 0.
std::unique_ptr<Density> MakeMeanCurvatureDensity(double floor);

}  // namespace sfc

#endif  // SFCSAMPLER_CORE_DENSITY_H_
