#include "engine/cad_jobs.h"

#include <malloc.h>

#include <algorithm>
#include <utility>

#include "absl/strings/str_format.h"
#include "cad/load.h"
#include "cad/model_sampler.h"
#include "catalog/catalog.h"
#include "core/status_macros.h"

namespace sfc {
namespace {

// Heap bytes in use now (glibc), for what a parse keeps: OpenCASCADE's
// objects have no size of their own to ask.
uint64_t HeapInUse() {
  const struct mallinfo2 info = mallinfo2();
  return info.uordblks + info.hblkhd;
}

absl::StatusOr<std::shared_ptr<const cad::Model>> LoadCad(const StoredModel& model,
                                                          LoadedModels* loaded,
                                                          const std::function<absl::Status()>& caller) {
  // The parse owns its inputs: it runs on a parse thread and may outlive the
  // request that started it.
  return loaded->Get<cad::Model>(
      model.Spec(),
      [model](const ParseCheck& check) -> absl::StatusOr<LoadedModels::Parsed> {
        ASSIGN_OR_RETURN(const cad::ModelFormat format,
                         cad::ParseModelFormat(std::string(ModelFormatName(model.format))));
        cad::LoadOptions options;
        options.max_bytes = std::max<size_t>(options.max_bytes, model.bytes->size());
        options.check = check;
        const uint64_t before = HeapInUse();
        ASSIGN_OR_RETURN(std::shared_ptr<const cad::Model> parsed,
                         cad::Load(format, *model.bytes, model.name.empty() ? model.Spec() : model.name,
                                   options));
        const uint64_t after = HeapInUse();
        // What the model holds: the heap's growth across the load (other
        // threads' allocations make this approximate), at least 4 KiB a face.
        const uint64_t bytes =
            std::max<uint64_t>(after > before ? after - before : 0, 4096 * parsed->faces().size());
        return LoadedModels::Parsed{std::move(parsed), bytes};
      },
      caller);
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
                                         const CurveTreeOptions& options, LoadedModels* loaded,
                                         const std::function<absl::Status()>& caller) {
  ASSIGN_OR_RETURN(DensityFromSpec d, MakeDensity(density));
  ASSIGN_OR_RETURN(std::shared_ptr<const cad::Model> cad_model, LoadCad(model, loaded, caller));
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
  ASSIGN_OR_RETURN(std::shared_ptr<const cad::Model> cad_model, LoadCad(model, loaded, nullptr));
  return cad::DescribeModel(*cad_model);
}

}  // namespace sfc
