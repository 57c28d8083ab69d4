#include "core/density.h"

#include <algorithm>
#include <cmath>

namespace sfc {
namespace {

class Uniform final : public Density {
 public:
  double Value(const SurfacePoint&) const override { return 1.0; }
  bool IsUniform() const override { return true; }
};

class GaussianCurvature final : public Density {
 public:
  explicit GaussianCurvature(double floor) : floor_(floor) {}
  bool NeedsCurvature() const override { return true; }
  double Value(const SurfacePoint& p) const override {
    return std::max(std::fabs(p.gaussian_curvature), floor_);
  }

 private:
  const double floor_;
};

class MeanCurvature final : public Density {
 public:
  explicit MeanCurvature(double floor) : floor_(floor) {}
  bool NeedsCurvature() const override { return true; }
  double Value(const SurfacePoint& p) const override {
    return std::max(std::fabs(p.mean_curvature), floor_);
  }

 private:
  const double floor_;
};

}  // namespace

double Density::UpperBound(const Surface&, double, double, double, double) const {
  return INFINITY;
}

std::unique_ptr<Density> MakeUniformDensity() { return std::make_unique<Uniform>(); }
std::unique_ptr<Density> MakeGaussianCurvatureDensity(double floor) {
  return std::make_unique<GaussianCurvature>(floor);
}
std::unique_ptr<Density> MakeMeanCurvatureDensity(double floor) {
  return std::make_unique<MeanCurvature>(floor);
}

}  // namespace sfc
