#include "kinds/mesh/mesh_kind.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <utility>

#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_replace.h"
#include "base/status_macros.h"
#include "catalog/catalog.h"
#include "catalog/expression.h"
#include "engine/batch_cursor.h"
#include "engine/float32_range.h"
#include "mesh/mesh_curve_tree.h"
#include "mesh/mesh_loader.h"
#include "mesh/mesh_sampler.h"

namespace sfc {

// A mesh's tree describes itself by its size alone, which TypedTree fills
// (engine/tree_source.h; the size includes the mesh it keeps alive).
void FillTreeSummary(const MeshCurveTree& tree, TreeSummary* out) {}

namespace {

struct MeshDensityChoice {
  std::shared_ptr<const MeshDensity> density;
  std::string canonical;
  std::string weight_property;  // vertex:NAME
};

absl::StatusOr<MeshDensityChoice> ParseMeshDensity(const std::string& text) {
  const std::string spec(absl::StripAsciiWhitespace(text));
  MeshDensityChoice out;
  if (absl::StartsWith(spec, "vertex:")) {
    out.weight_property = std::string(absl::StripAsciiWhitespace(spec.substr(7)));
    if (out.weight_property.empty()) {
      return absl::InvalidArgumentError(
          "density vertex: needs the name of a PLY vertex property, e.g. vertex:quality");
    }
    out.density = VertexWeightMeshDensity();
    out.canonical = "vertex:" + out.weight_property;
    return out;
  }
  if (absl::StartsWith(spec, "expr:")) {
    const std::string body(absl::StripAsciiWhitespace(spec.substr(5)));
    ASSIGN_OR_RETURN(
        std::shared_ptr<const Expression> f,
        Expression::Compile("mesh density expression (in x, y, z)", body, {"x", "y", "z"}));
    out.density = std::make_shared<FunctionMeshDensity>(
        [f](const MeshPoint& p) {
          const double xyz[3] = {p.position.x, p.position.y, p.position.z};
          return f->Evaluate(xyz);
        },
        "expr:" + body);
    out.canonical = "expr:" + body;
    return out;
  }
  // Catalogue densities: validated and made canonical by the catalogue, with
  // the catalogue's meaning. Meshes add gaussian:offset=F and mean:offset=F
  // (|K| + F), whose number the catalogue reads as a floor's.
  const bool offset = (absl::StartsWith(spec, "gaussian:") || absl::StartsWith(spec, "mean:")) &&
                      absl::StrContains(spec, "offset=");
  ASSIGN_OR_RETURN(const DensityFromSpec catalog,
                   MakeDensity(offset ? absl::StrReplaceAll(spec, {{"offset=", "floor="}}) : spec));
  out.canonical = offset ? absl::StrReplaceAll(catalog.canonical, {{"floor=", "offset="}})
                         : catalog.canonical;
  const CurvatureFloor rule = offset ? CurvatureFloor::kOffset : CurvatureFloor::kMax;
  if (catalog.name == "uniform") {
    out.density = UniformMeshDensity();
    return out;
  }
  if (catalog.name == "gaussian" || catalog.name == "mean") {
    const double floor = catalog.parameters.at("floor");
    if (!offset && floor > 0) {
      // Algorithm version sfcsampler-3 gave |K| + F for this spec on meshes;
      // max(|K|, F) would give other bytes under the same version.
      return absl::InvalidArgumentError(absl::StrFormat(
          "on meshes, %s:floor=F (max(|K|, F), its meaning on other surfaces) waits for the next "
          "algorithm version; write %s:offset=%g for |K| + F, what sfcsampler-3 gives meshes",
          catalog.name, catalog.name, floor));
    }
    out.density = catalog.name == "gaussian" ? GaussianCurvatureMeshDensity(floor, rule)
                                             : MeanCurvatureMeshDensity(floor, rule);
    return out;
  }
  return absl::InvalidArgumentError(absl::StrFormat(
      "density \"%s\" is not available on meshes; use uniform, gaussian, mean, "
      "gaussian:offset=F, mean:offset=F (|K| + F), "
      "expr:EXPRESSION in x, y, z, or vertex:PROPERTY",
      spec));
}

// What a kept mesh surface costs: its arrays (positions, triangles,
// normals, weights, face normals, curvature).
uint64_t MeshSurfaceBytes(const MeshSurface& surface) {
  const TriangleMesh& m = surface.mesh();
  const VertexCurvature& k = surface.curvature();
  return sizeof(MeshSurface) + m.positions.capacity() * sizeof(Vec3) +
         m.triangles.capacity() * sizeof(m.triangles[0]) + m.normals.capacity() * sizeof(Vec3) +
         m.weights.capacity() * sizeof(double) + surface.triangle_count() * sizeof(Vec3) +
         (k.gaussian.capacity() + k.mean.capacity() + k.mixed_area.capacity()) * sizeof(double);
}

struct MeshTreeRecipe {
  std::string canonical_density;
  TreeFactory factory;
  std::function<ValueExtent()> measure;  // ResolvedSurface::measure
};

// Parses `density` for a mesh, loads `model` (through `loaded`, on its parse
// threads; `caller` is asked while the request waits) as that density needs
// it, and returns how to build its tree, its triangles ordered on `threads`
// threads (the same tree for any count). `tolerance` 0 takes the mesh tree's
// default.
absl::StatusOr<MeshTreeRecipe> MeshTreeFor(const StoredModel& model, const std::string& density,
                                           double tolerance, uint64_t max_leaves, int threads,
                                           LoadedModels* loaded,
                                           const std::function<absl::Status()>& caller) {
  ASSIGN_OR_RETURN(MeshDensityChoice choice, ParseMeshDensity(density));
  const bool curvature = choice.density->needs_curvature();
  const std::string key = absl::StrCat(model.Spec(), "|curvature=", curvature,
                                       "|weights=", choice.weight_property);
  MeshLoadOptions options;
  options.format = model.format;
  options.weight_property = choice.weight_property;
  options.max_bytes = model.bytes->size();
  const uint64_t working_bytes = MeshParseMemoryBytes(model.format, *model.bytes);
  // The parse owns its inputs: it runs on a parse thread and may outlive the
  // request that started it.
  ASSIGN_OR_RETURN(
      std::shared_ptr<const MeshSurface> surface,
      loaded->Get<MeshSurface>(
          key,
          [model, options, curvature](const ParseCheck& check) mutable
          -> absl::StatusOr<LoadedModels::Parsed> {
            options.check = check;
            const std::string name = model.name.empty() ? model.Spec() : model.name;
            ASSIGN_OR_RETURN(TriangleMesh mesh, LoadMesh(*model.bytes, name, options));
            RETURN_IF_ERROR(check());
            std::shared_ptr<const MeshSurface> parsed =
                MeshSurface::Create(std::move(mesh), curvature);
            const uint64_t bytes = MeshSurfaceBytes(*parsed);
            return LoadedModels::Parsed{std::move(parsed), bytes};
          },
          caller, working_bytes));
  MeshTreeRecipe recipe;
  recipe.canonical_density = choice.canonical;
  // The box FinalizeMesh found holds every sample (MeshStats::lo, hi). The
  // density column is left to the cursor.
  recipe.measure = [surface] {
    const MeshStats& stats = surface->mesh().stats;
    ValueExtent extent;
    extent.measured = true, extent.lo = stats.lo, extent.hi = stats.hi;
    return extent;
  };
  recipe.factory.build = [surface, density = choice.density, tolerance, max_leaves, threads](
                             int grade, const BuildControl& control) -> TreeFactory::Result {
    RETURN_IF_ERROR(control.check ? control.check() : absl::OkStatus());
    MeshTreeOptions options;
    options.count = uint64_t{1} << grade;
    options.threads = std::max(1, threads);
    if (tolerance > 0) options.tolerance = tolerance;
    options.max_leaves = max_leaves;
    ASSIGN_OR_RETURN(std::shared_ptr<const MeshCurveTree> tree,
                     MeshCurveTree::Build(surface, density, options));
    // A kept tree keeps its mesh alive, also after the parsed-model budget
    // let the mesh go: the tree's cost includes it, so the tree cache's
    // budget bounds what its trees pin (counted twice while both keep it).
    const uint64_t bytes = tree->stats().bytes + MeshSurfaceBytes(*surface);
    const uint64_t leaves = tree->leaf_count();
    return std::make_shared<const TypedTree<MeshCurveTree>>(std::move(tree), bytes, leaves);
  };
  return recipe;
}

absl::StatusOr<std::unique_ptr<BatchCursor>> OpenMeshCursor(const TreeLookup& lookup,
                                                            Sequence sequence,
                                                            const CursorSpec& spec) {
  auto mesh_tree = TreeAs<MeshCurveTree>(lookup.any.get());
  if (!mesh_tree) return absl::InternalError("a mesh request found a tree of another kind");
  auto sampler = std::make_shared<const MeshSampler>(std::move(mesh_tree), std::move(sequence));
  ASSIGN_OR_RETURN(auto cursor, SampleCursor::Create(std::move(sampler), spec.begin, spec.end,
                                                     spec.region, spec.fields, spec.threads));
  return std::make_unique<SurfaceBatchCursor>(std::move(cursor));
}

class MeshKind final : public SurfaceKind {
 public:
  const KindInfo& info() const override {
    static const KindInfo* const info = new KindInfo{"mesh",
                                                     "a mesh surface (obj: or ply:)",
                                                     {ModelFormat::kObj, ModelFormat::kPly},
                                                     /*face_column=*/false,
                                                     /*triangle_column=*/true};
    return *info;
  }

  absl::StatusOr<ResolvedSurface> Resolve(const TreeSpec& spec, const StoredModel* model,
                                          const KindContext& context) const override {
    if (!model) return absl::InternalError("the mesh kind was given a spec that names no model");
    ASSIGN_OR_RETURN(MeshTreeRecipe recipe,
                     MeshTreeFor(*model, spec.density, spec.options.tolerance,
                                 context.limits->max_tree_leaves,
                                 context.limits->generation_threads, context.loaded,
                                 context.caller));
    CurveTreeOptions options;  // a mesh's curve has no options but the tolerance
    options.tolerance = spec.options.tolerance;
    ResolvedSurface out;
    out.key = MakeTreeKey(model->Spec(), recipe.canonical_density, options);
    out.factory = std::move(recipe.factory);
    out.open_cursor = OpenMeshCursor;
    out.measure = std::move(recipe.measure);
    out.forget = [loaded = context.loaded, sha256 = model->sha256] { loaded->ForgetModel(sha256); };
    return out;
  }
};

}  // namespace

std::unique_ptr<const SurfaceKind> MakeMeshKind() { return std::make_unique<MeshKind>(); }

}  // namespace sfc
