// The CAD kind itself, built as the module libsfcsampler-cad.so
// (kinds/module_kind.h): the only code that links OpenCASCADE's libraries
// into a program, loaded when a request first names a CAD model.
#include <malloc.h>

#include <algorithm>
#include <utility>

#include "absl/strings/str_format.h"
#include "base/status_macros.h"
#include "base/worker_pool.h"
#include "cad/load.h"
#include "cad/model_sampler.h"
#include "kinds/cad/cad_kind.h"
#include "kinds/cad/model_check.h"
#include "kinds/module_kind.h"
#include "catalog/catalog.h"

namespace sfc {
namespace cad {

// A model's trees (one per face) describe themselves by their size alone,
// which TypedTree fills (engine/tree_source.h; the size includes the parsed
// model they keep alive).
void FillTreeSummary(const ModelTree& tree, TreeSummary* out) {}

}  // namespace cad
namespace {

// Heap bytes in use now (glibc), for what a parse keeps: OpenCASCADE's
// objects have no size of their own to ask.
uint64_t HeapInUse() {
  const struct mallinfo2 info = mallinfo2();
  return info.uordblks + info.hblkhd;
}

// A parsed model and what keeping it costs.
struct CadParse {
  std::shared_ptr<const cad::Model> model;
  uint64_t bytes = 0;
};

absl::StatusOr<std::shared_ptr<const CadParse>> LoadCad(const StoredModel& model,
                                                        const KindContext& context) {
  // The parse's peak memory (bench/parse_memory, docs/MODELS.md): 22-26
  // bytes a byte of a 8-10 MB STEP or IGES file, past the kernel's one-time
  // ~16 MB; reserved with a margin.
  const uint64_t working_bytes = (uint64_t{1} << 20) + 30 * model.bytes->size();
  ModelCheckLimits check_limits;
  check_limits.program = context.limits->model_check_program;
  check_limits.cpu_seconds = context.limits->ParseSecondsFor(model.bytes->size());
  check_limits.yield_seconds = context.limits->model_parse_fresh_seconds;
  // The check process's address space. Measured (RLIMIT_AS given to
  // sfcsampler-model-check): the 22 KB box reads within 100 MiB; the 10 MB
  // STEP of 400 boxes (working_bytes 301 MB) is out of memory at 300 MiB
  // and reads at 400 MiB. The limit leaves a wide margin over that.
  check_limits.memory_bytes = (uint64_t{1} << 30) + 2 * working_bytes;
  // The parse owns its inputs: it runs on a parse thread and may outlive the
  // request that started it.
  return context.loaded->Get<CadParse>(
      model.Spec(),
      [model, check_limits](const ParseCheck& check) -> absl::StatusOr<LoadedModels::Parsed> {
        if (!cad::IsCadFormat(model.format)) {
          return absl::InternalError("the CAD kind was given a model of another format");
        }
        const ModelFormat format = model.format;
        const std::string name = model.name.empty() ? model.Spec() : model.name;
        cad::LoadOptions options;
        options.max_bytes = std::max<size_t>(options.max_bytes, model.bytes->size());
        options.check = check;
        // A server reads the file in the check process and makes the model of
        // the shape it sends back; the CLI reads the user's own file here.
        std::string brep;
        if (!check_limits.program.empty()) {
          ASSIGN_OR_RETURN(brep, ReadModelInSubprocess(check_limits, model.format, *model.bytes,
                                                       name, check));
        }
        const uint64_t before = HeapInUse();
        ASSIGN_OR_RETURN(std::shared_ptr<const cad::Model> parsed,
                         check_limits.program.empty()
                             ? cad::Load(format, *model.bytes, name, options)
                             : cad::LoadBrep(brep, format, name, options));
        const uint64_t after = HeapInUse();
        // What the model holds: the heap's growth across the load (other
        // threads' allocations make this approximate), at least 4 KiB a face.
        const uint64_t bytes =
            std::max<uint64_t>(after > before ? after - before : 0, 4096 * parsed->faces().size());
        return LoadedModels::Parsed{
            std::make_shared<const CadParse>(CadParse{std::move(parsed), bytes}), bytes};
      },
      context.caller, working_bytes);
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

class CadKind final : public SurfaceKind {
 public:
  const KindInfo& info() const override { return CadKindInfo(); }

  absl::StatusOr<ResolvedSurface> Resolve(const TreeSpec& spec, const StoredModel* model,
                                          const KindContext& context) const override {
    if (!model) return absl::InternalError("the CAD kind was given a spec that names no model");
    CurveTreeOptions options = spec.options;
    options.max_leaves = context.limits->max_tree_leaves;
    ASSIGN_OR_RETURN(DensityFromSpec density, MakeDensity(spec.density));
    ASSIGN_OR_RETURN(std::shared_ptr<const CadParse> parse,
                     LoadCad(*model, context));
    ResolvedSurface out;
    out.key = MakeTreeKey(model->Spec(), density.canonical, options);
    out.factory.build = [parse, density = density.density, options](
                            int grade, const BuildControl& control) -> TreeFactory::Result {
      ASSIGN_OR_RETURN(std::shared_ptr<const cad::ModelTree> tree,
                       cad::ModelTree::Build(parse->model, density, options, uint64_t{1} << grade,
                                             control));
      // A kept tree keeps its model alive, also after the parsed-model budget
      // let the model go: the tree's cost includes it (as a mesh tree's does).
      const uint64_t bytes = tree->bytes() + parse->bytes;
      const uint64_t leaves = tree->leaf_count();
      return std::make_shared<const TypedTree<cad::ModelTree>>(std::move(tree), bytes, leaves);
    };
    out.open_cursor = [](const TreeLookup& lookup, Sequence sequence,
                         const CursorSpec& spec) -> absl::StatusOr<std::unique_ptr<BatchCursor>> {
      auto model_tree = TreeAs<cad::ModelTree>(lookup.any.get());
      if (!model_tree) return absl::InternalError("a CAD request found a tree of another kind");
      ASSIGN_OR_RETURN(auto cursor, cad::ModelSampleCursor::Create(
                                        std::move(model_tree), sequence, spec.begin, spec.end,
                                        spec.region, spec.fields, spec.threads));
      return std::make_unique<CadBatchCursor>(std::move(cursor));
    };
    out.forget = [loaded = context.loaded, sha256 = model->sha256] { loaded->ForgetModel(sha256); };
    return out;
  }

  absl::StatusOr<std::string> Describe(const StoredModel& model,
                                       const KindContext& context) const override {
    ASSIGN_OR_RETURN(std::shared_ptr<const CadParse> parse,
                     LoadCad(model, context));
    return cad::DescribeModel(*parse->model);
  }
};

}  // namespace

}  // namespace sfc

// The module's entry points (kinds/module_kind.h); the only symbols it exports.
extern "C" {
const char* sfcsampler_kind_module_abi() {
  static const std::string* const abi = new std::string(sfc::KindModuleAbi());
  return abi->c_str();
}
sfc::SurfaceKind* sfcsampler_make_cad_kind(sfc::WorkerPool* pool) {
  sfc::WorkerPool::ShareFrom(pool);
  return new sfc::CadKind();
}
}
