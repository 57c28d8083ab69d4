#include "engine/cad_jobs.h"

#include <utility>

#include "absl/strings/str_format.h"
#include "cad/load.h"
#include "cad/model_sampler.h"
#include "catalog/catalog.h"
#include "core/status_macros.h"

namespace sfc {
namespace {

absl::StatusOr<std::shared_ptr<const cad::Model>> LoadCad(const StoredModel& model,
                                                          LoadedModels* loaded) {
  return loaded->Get<cad::Model>(
      model.Spec(), [&]() -> absl::StatusOr<std::shared_ptr<const cad::Model>> {
        ASSIGN_OR_RETURN(const cad::ModelFormat format,
                         cad::ParseModelFormat(std::string(ModelFormatName(model.format))));
        cad::LoadOptions options;
        options.max_bytes = std::max<size_t>(options.max_bytes, model.bytes->size());
        return cad::Load(format, *model.bytes, model.name.empty() ? model.Spec() : model.name,
                         options);
      });
}

class CadBatchCursor final : public BatchCursor {
 public:
  explicit CadBatchCursor(std::unique_ptr<cad::ModelSampleCursor> cursor)
      : cursor_(std::move(cursor)) {}
  absl::StatusOr<size_t> Next(size_t max, SampleBatch* batch) override {
    return cursor_->Next(max, batch);
  }

 private:
  std::unique_ptr<cad::ModelSampleCursor> cursor_;
};

}  // namespace

absl::StatusOr<CadTreeRecipe> CadTreeFor(const StoredModel& model, const std::string& density,
                                         const CurveTreeOptions& options, LoadedModels* loaded) {
  ASSIGN_OR_RETURN(DensityFromSpec d, MakeDensity(density));
  ASSIGN_OR_RETURN(std::shared_ptr<const cad::Model> cad_model, LoadCad(model, loaded));
  CadTreeRecipe recipe;
  recipe.canonical_density = d.canonical;
  recipe.factory.build = [cad_model, density = d.density, options](
                             int grade, const BuildControl& control) -> TreeFactory::Result {
    ASSIGN_OR_RETURN(std::shared_ptr<const cad::ModelTree> tree,
                     cad::ModelTree::Build(cad_model, density, options, uint64_t{1} << grade, control));
    const uint64_t bytes = tree->bytes(), leaves = tree->leaf_count();
    return std::make_shared<const TypedTree<cad::ModelTree>>(std::move(tree), bytes, leaves);
  };
  return recipe;
}

absl::StatusOr<std::unique_ptr<BatchCursor>> CadCursor(const AnyTree& tree, Sequence sequence,
                                                       uint64_t begin, uint64_t end,
                                                       const Region& region,
                                                       const SampleFields& fields, int threads) {
  auto model_tree = TreeAs<cad::ModelTree>(&tree);
  if (!model_tree) return absl::InternalError("a CAD request found a tree of another kind");
  ASSIGN_OR_RETURN(auto cursor, cad::ModelSampleCursor::Create(std::move(model_tree), sequence,
                                                               begin, end, region, fields, threads));
  return std::make_unique<CadBatchCursor>(std::move(cursor));
}

absl::StatusOr<std::string> DescribeCadModel(const StoredModel& model, LoadedModels* loaded) {
  ASSIGN_OR_RETURN(std::shared_ptr<const cad::Model> cad_model, LoadCad(model, loaded));
  return cad::DescribeModel(*cad_model);
}

}  // namespace sfc
