#include "mesh/mesh_density.h"

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
  Curvature(bool gaussian, double floor) : gaussian_(gaussian), floor_(floor) {}
  double Evaluate(const MeshPoint& p) const override {
    return std::abs(gaussian_ ? p.gaussian_curvature : p.mean_curvature) + floor_;
  }
  bool needs_curvature() const override { return true; }
  std::string spec() const override {
    return absl::StrFormat("%s:floor=%.17g", gaussian_ ? "gaussian" : "mean", floor_);
  }

 private:
  bool gaussian_;
  double floor_;
};

}  // namespace

std::shared_ptr<const MeshDensity> UniformMeshDensity() { return std::make_shared<Uniform>(); }
std::shared_ptr<const MeshDensity> VertexWeightMeshDensity() {
  return std::make_shared<VertexWeight>();
}
std::shared_ptr<const MeshDensity> GaussianCurvatureMeshDensity(double floor) {
  return std::make_shared<Curvature>(true, floor);
}
std::shared_ptr<const MeshDensity> MeanCurvatureMeshDensity(double floor) {
  return std::make_shared<Curvature>(false, floor);
}

}  // namespace sfc
