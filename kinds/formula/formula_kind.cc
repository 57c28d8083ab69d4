#include "kinds/formula/formula_kind.h"

#include <utility>

#include "base/status_macros.h"
#include "catalog/catalog.h"
#include "core/curve_tree.h"
#include "core/sampler.h"
#include "engine/float32_range.h"

namespace sfc {
namespace {

class FormulaKind final : public SurfaceKind {
 public:
  const KindInfo& info() const override {
    static const KindInfo* const info = new KindInfo{"surface", "a formula surface", {}};
    return *info;
  }

  absl::StatusOr<ResolvedSurface> Resolve(const TreeSpec& spec, const StoredModel* model,
                                          const KindContext& context) const override {
    ASSIGN_OR_RETURN(SurfaceFromSpec surface, MakeSurface(spec.surface));
    ASSIGN_OR_RETURN(DensityFromSpec density, MakeDensity(spec.density));
    CurveTreeOptions options = spec.options;
    options.max_leaves = context.limits->max_tree_leaves;  // the server's budget, not the request's
    ResolvedSurface out;
    out.key = MakeTreeKey(surface.canonical, density.canonical, options);
    out.factory.build = [surface = surface.surface, density = density.density, options](
                            int grade, const BuildControl& control) -> TreeFactory::Result {
      return AsAnyTree(CurveTree::Build(*surface, *density, options, grade, control));
    };
    out.factory.refine = [surface = surface.surface, density = density.density](
                             const AnyTree& coarser, int grade,
                             const BuildControl& control) -> TreeFactory::Result {
      const auto tree = TreeAs<CurveTree>(&coarser);
      if (!tree) return absl::InternalError("refining a tree of another kind");
      return AsAnyTree(tree->Refined(*surface, *density, grade, control));
    };
    out.open_cursor = [surface = surface.surface, density = density.density](
                          const TreeLookup& lookup, Sequence sequence,
                          const CursorSpec& spec) -> absl::StatusOr<std::unique_ptr<BatchCursor>> {
      auto tree = TreeAs<CurveTree>(lookup.any.get());
      if (!tree) return absl::InternalError("a formula surface found a tree of another kind");
      auto sampler =
          std::make_shared<const Sampler>(std::move(tree), surface, density, std::move(sequence));
      ASSIGN_OR_RETURN(std::unique_ptr<SampleCursor> cursor,
                       SampleCursor::Create(std::move(sampler), spec.begin, spec.end, spec.region,
                                            spec.fields, spec.threads));
      return std::make_unique<SurfaceBatchCursor>(std::move(cursor));
    };
    out.measure = [surface = surface.surface, density = density.density] {
      return MeasureValues(*surface, *density);
    };
    return out;
  }
};

}  // namespace

std::unique_ptr<const SurfaceKind> MakeFormulaKind() { return std::make_unique<FormulaKind>(); }

}  // namespace sfc
