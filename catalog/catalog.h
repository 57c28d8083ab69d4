// The catalogue of surfaces and densities, made from text specifications.
//
// Spec syntax: NAME or NAME:KEY=VALUE;KEY=VALUE... Numeric values are
// constant muparser expressions ("2*_pi", "1/3"). Examples:
//   sphere                       torus:R=2;r=0.5
//   superellipsoid:e=1/3;reparam=1
//   expr:x=cos(u)*cos(v);y=cos(u)*sin(v);z=sin(u);u0=-_pi/2;u1=_pi/2;v0=-_pi;v1=_pi
//   gaussian:floor=0.05          expr:u+v
// Every spec has a canonical form (all parameters, fixed order, full
// precision) that identifies it in cache keys.
//
// Thread-safety: all functions are thread-safe; the returned objects are
// immutable and thread-safe.
#ifndef SFCSAMPLER_CATALOG_CATALOG_H_
#define SFCSAMPLER_CATALOG_CATALOG_H_

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/density.h"
#include "core/surface.h"

namespace sfc {

struct CatalogParameter {
  std::string name;
  std::string default_value;  // empty: required
  std::string meaning;
};

struct CatalogEntry {
  std::string name;
  std::string formula;
  std::string description;
  std::vector<CatalogParameter> parameters;
};

const std::vector<CatalogEntry>& SurfaceCatalog();
const std::vector<CatalogEntry>& DensityCatalog();

struct SurfaceFromSpec {
  std::shared_ptr<const Surface> surface;
  std::string canonical;
};
struct DensityFromSpec {
  std::shared_ptr<const Density> density;
  std::string canonical;
  // The catalogue entry ("uniform", "gaussian", "mean", "expr") and its
  // parameters' values (gaussian and mean: "floor"), for other kinds of
  // surface that give the same density their own form (meshes).
  std::string name;
  std::map<std::string, double> parameters;
};

// Errors: INVALID_ARGUMENT for an unknown name or parameter, a malformed
// value or expression (with its position), or a value out of range.
absl::StatusOr<SurfaceFromSpec> MakeSurface(const std::string& spec);
absl::StatusOr<DensityFromSpec> MakeDensity(const std::string& spec);

}  // namespace sfc

#endif  // SFCSAMPLER_CATALOG_CATALOG_H_
