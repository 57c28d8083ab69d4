// Densities on a triangle mesh: delta >= 0 as a function of the point and of
// the vertex attributes interpolated to it (per-vertex weights read from the
// file, discrete curvature by Meyer et al. 2003, see mesh/curvature.h).
//
// Expressions in x, y, z (catalog/) plug in as a MeshDensity subclass or as
// FunctionMeshDensity. Thread-safety: implementations must be safe to call
// from several threads at once (trees and cursors of one mesh may run
// concurrently); the built-ins are immutable.
#ifndef SFCSAMPLER_MESH_MESH_DENSITY_H_
#define SFCSAMPLER_MESH_MESH_DENSITY_H_

#include <functional>
#include <memory>
#include <string>

#include "core/types/vec3.h"

namespace sfc {

// What a density sees at a point of triangle t with barycentric coordinates
// (w, u, v) for its corners (0, 1, 2): every field is the barycentric
// interpolation of the corners' values (the point lies on the flat triangle).
struct MeshPoint {
  Vec3 position;
  double weight = 1;              // per-vertex weight; 1 when the mesh has none
  double gaussian_curvature = 0;  // K; 0 unless the density needs_curvature()
  double mean_curvature = 0;      // H (signed); 0 unless the density needs_curvature()
};

class MeshDensity {
 public:
  virtual ~MeshDensity() = default;
  // delta at `p`: finite and >= 0 (a violation makes sampling fail with
  // INVALID_ARGUMENT).
  virtual double Evaluate(const MeshPoint& p) const = 0;
  // True when delta is 1 everywhere: masses are exact areas and nothing is evaluated.
  virtual bool uniform() const { return false; }
  virtual bool needs_curvature() const { return false; }
  virtual bool needs_weights() const { return false; }
  // A canonical description, for cache keys and messages ("uniform", ...).
  virtual std::string spec() const = 0;
};

// delta = 1.
std::shared_ptr<const MeshDensity> UniformMeshDensity();
// delta = interpolated per-vertex weight. REQUIRES: the mesh has weights
// (MeshLoadOptions::weight_property); otherwise building a tree fails.
std::shared_ptr<const MeshDensity> VertexWeightMeshDensity();
// How a curvature density keeps flat regions sampled: max(|K|, f), the rule
// of the catalogue's gaussian:floor=F and mean:floor=F on every kind of
// surface; or |K| + f, meshes' gaussian:offset=F and mean:offset=F.
enum class CurvatureFloor { kMax, kOffset };
// delta from |K| (gaussian) or |H| (mean), per-vertex curvature interpolated
// linearly, kept off zero by `f` as `rule` says. REQUIRES: f >= 0.
std::shared_ptr<const MeshDensity> GaussianCurvatureMeshDensity(
    double f, CurvatureFloor rule = CurvatureFloor::kMax);
std::shared_ptr<const MeshDensity> MeanCurvatureMeshDensity(
    double f, CurvatureFloor rule = CurvatureFloor::kMax);

// Wraps a callable (e.g. a catalog expression in x, y, z).
class FunctionMeshDensity : public MeshDensity {
 public:
  FunctionMeshDensity(std::function<double(const MeshPoint&)> f, std::string spec,
                      bool needs_curvature = false, bool needs_weights = false)
      : f_(std::move(f)), spec_(std::move(spec)), curvature_(needs_curvature),
        weights_(needs_weights) {}
  double Evaluate(const MeshPoint& p) const override { return f_(p); }
  bool needs_curvature() const override { return curvature_; }
  bool needs_weights() const override { return weights_; }
  std::string spec() const override { return spec_; }

 private:
  std::function<double(const MeshPoint&)> f_;
  std::string spec_;
  bool curvature_, weights_;
};

}  // namespace sfc

#endif  // SFCSAMPLER_MESH_MESH_DENSITY_H_
