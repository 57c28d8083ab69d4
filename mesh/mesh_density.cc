#include "mesh/mesh_density.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_format.h"

namespace sfc {
namespace {

class Uniform : public MeshDensity {
 public:
  double Evaluate(const MeshPoint&) const override { return 1; }
  bool uniform() const override { return true; }
  std::string spec() const override { return "uniform"; }
};

class VertexWeight : public MeshDensity {
 public:
  double Evaluate(const MeshPoint& p) const override { return p.weight; }
  bool needs_weights() const override { return true; }
  std::string spec() const override { return "weight"; }
};

class Curvature : public MeshDensity {
 public:
  Curvature(bool gaussian, double f, CurvatureFloor rule)
      : gaussian_(gaussian), f_(f), rule_(rule) {}
  double Evaluate(const MeshPoint& p) const override {
    const double k = std::abs(gaussian_ ? p.gaussian_curvature : p.mean_curvature);
    return rule_ == CurvatureFloor::kMax ? std::max(k, f_) : k + f_;
  }
  bool needs_curvature() const override { return true; }
  std::string spec() const override {
    return absl::StrFormat("%s:%s=%.17g", gaussian_ ? "gaussian" : "mean",
                           rule_ == CurvatureFloor::kMax ? "floor" : "offset", f_);
  }

 private:
  bool gaussian_;
  double f_;
  CurvatureFloor rule_;
};

}  // namespace

std::shared_ptr<const MeshDensity> UniformMeshDensity() { return std::make_shared<Uniform>(); }
std::shared_ptr<const MeshDensity> VertexWeightMeshDensity() {
  return std::make_shared<VertexWeight>();
}
std::shared_ptr<const MeshDensity> GaussianCurvatureMeshDensity(double f, CurvatureFloor rule) {
  return std::make_shared<Curvature>(true, f, rule);
}
std::shared_ptr<const MeshDensity> MeanCurvatureMeshDensity(double f, CurvatureFloor rule) {
  return std::make_shared<Curvature>(false, f, rule);
}

}  // namespace sfc
