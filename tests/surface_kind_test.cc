// The seam for kinds of surface (engine/surface_kind.h): the engine samples
// whatever kinds it is given and refuses the rest with a clear error, and a
// new kind needs no change to the engine.
#include "engine/surface_kind.h"

#include <algorithm>
#include <fstream>
#include <string>
#include <memory>
#include <utility>
#include <vector>

#include "engine/sampling_engine.h"
#include "gtest/gtest.h"
#include "kinds/formula/formula_kind.h"
#include "kinds/module_kind.h"
#include "base/worker_pool.h"
#include "kinds/registered_kinds.h"
#include "tests/engine_helpers.h"

namespace sfc {
namespace {

SurfaceKinds FormulaOnly() {
  std::vector<std::unique_ptr<const SurfaceKind>> kinds;
  kinds.push_back(MakeFormulaKind());
  return SurfaceKinds(std::move(kinds));
}

void ExpectError(const absl::Status& status, absl::StatusCode code, const std::string& mentions) {
  EXPECT_EQ(status.code(), code) << status;
  EXPECT_NE(status.message().find(mentions), std::string::npos)
      << "message \"" << status.message() << "\" should mention \"" << mentions << "\"";
}

TEST(SurfaceKinds, AModelWithoutItsKindIsRefusedByName) {
  const SurfaceKinds kinds = FormulaOnly();
  DirectTreeSource source;
  FileModelSource files;
  SamplingEngine engine(kinds, {}, &source, &files);
  SampleRequest r;
  r.count = 100;
  r.tree.surface = "step:" + WriteTemp("kindless.step", "ISO-10303-21;");
  ExpectError(engine.Start(r).status(), absl::StatusCode::kUnimplemented, "step:");
  r.tree.surface = "sphere";
  r.fields.face = true;
  ExpectError(engine.Start(r).status(), absl::StatusCode::kInvalidArgument,
              "face column needs a kind of surface this build does not have");
  ExpectError(engine.DescribeModel("step:part.step").status(), absl::StatusCode::kUnimplemented,
              "inspect");
  r.fields.face = false;
  EXPECT_EQ(DrawAll(engine, r).size(), 100u);  // its own kind still works
}

TEST(SurfaceKinds, TheRegisteredKindsAreEachFoundForTheirSpecs) {
  const SurfaceKinds& kinds = RegisteredSurfaceKinds();
  const SurfaceKind* formula = kinds.For(std::nullopt);
  ASSERT_NE(formula, nullptr);
  EXPECT_EQ(formula->info().name, "surface");
  for (const ModelFormat format : {ModelFormat::kStep, ModelFormat::kIges, ModelFormat::kNurbs,
                                   ModelFormat::kObj, ModelFormat::kPly}) {
    const SurfaceKind* kind = kinds.For(ModelSpec{format, "x", ""});
    if (!kind) continue;  // a build without that kind
    EXPECT_NE(kind, formula);
    const auto& formats = kind->info().formats;
    EXPECT_NE(std::find(formats.begin(), formats.end(), format), formats.end());
  }
}

// A kind the engine has never heard of: "ply:" files sampled as the unit
// square, whatever they hold. It only forwards to the formula kind.
class SquareFromPlyKind final : public SurfaceKind {
 public:
  const KindInfo& info() const override {
    static const KindInfo* const info = new KindInfo{"square", "a square", {ModelFormat::kPly}};
    return *info;
  }
  absl::StatusOr<ResolvedSurface> Resolve(const TreeSpec& spec, const StoredModel* model,
                                          const KindContext& context) const override {
    if (!model) return absl::InternalError("no model");
    TreeSpec plane = spec;
    plane.surface = "plane";
    return formula_->Resolve(plane, nullptr, context);
  }

 private:
  std::unique_ptr<const SurfaceKind> formula_ = MakeFormulaKind();
};

TEST(SurfaceKinds, ANewKindIsSampledWithoutChangingTheEngine) {
  std::vector<std::unique_ptr<const SurfaceKind>> list;
  list.push_back(MakeFormulaKind());
  list.push_back(std::make_unique<SquareFromPlyKind>());
  const SurfaceKinds kinds(std::move(list));
  DirectTreeSource source;
  FileModelSource files;
  SamplingEngine engine(kinds, {}, &source, &files);
  SampleRequest r;
  r.count = 1000;
  r.seed = 7;
  r.tree.surface = "ply:" + WriteTemp("anything.ply", "not a mesh at all");
  auto prepared = engine.Prepare(r.tree, r.count);
  ASSERT_TRUE(prepared.ok()) << prepared.status();
  EXPECT_EQ(prepared->kind, "square");  // named by its kind (TreeInfo.kind)
  const SampleBatch square = DrawAll(engine, r);
  r.tree.surface = "plane";
  const SampleBatch plane = DrawAll(engine, r);
  ASSERT_EQ(square.size(), 1000u);
  EXPECT_EQ(square.x, plane.x);  // the same tree and placement, reached through the new kind
  EXPECT_EQ(square.y, plane.y);
  r.fields.triangle = true;  // a column the new kind does not fill
  r.tree.surface = "ply:" + WriteTemp("anything.ply", "not a mesh at all");
  EXPECT_EQ(engine.Start(r).status().code(), absl::StatusCode::kInvalidArgument);
}

// A bilinear NURBS patch: the smallest CAD model, written without OpenCASCADE.
constexpr char kSheetNurbs[] =
    "sfcsampler-nurbs 1\ndegree 1 1\ncount 2 2\nknots_u 0 0 1 1\nknots_v 0 0 1 1\n"
    "pole 0 0 0\npole 0 1 0\npole 1 0 0\npole 1 1 0.5\n";

// The libraries this process has mapped whose path contains `name`.
int Mapped(const std::string& name) {
  std::ifstream maps("/proc/self/maps");
  int count = 0;
  for (std::string line; std::getline(maps, line);) count += line.find(name) != std::string::npos;
  return count;
}

// A kind whose module is missing fails with a clear error naming the file,
// where it was looked for and what to set; the other kinds still work.
TEST(ModuleKinds, AMissingModuleIsAClearErrorAndTheOtherKindsWork) {
  const KindInfo info{"model", "a test kind (nurbs:)", {ModelFormat::kNurbs}};
  std::vector<std::unique_ptr<const SurfaceKind>> list;
  list.push_back(MakeFormulaKind());
  list.push_back(MakeModuleKind(info, "libsfcsampler-nosuch.so", "nosuch_factory"));
  const SurfaceKinds kinds(std::move(list));
  DirectTreeSource source;
  FileModelSource files;
  SamplingEngine engine(kinds, {}, &source, &files);
  SampleRequest r;
  r.count = 100;
  r.tree.surface = "nurbs:" + WriteTemp("module.nurbs", "sfcsampler-nurbs 1\n");
  for (int attempt = 0; attempt < 2; ++attempt) {  // the second from the remembered failure
    const absl::Status status = engine.Start(r).status();
    ExpectError(status, absl::StatusCode::kFailedPrecondition, "libsfcsampler-nosuch.so");
    ExpectError(status, absl::StatusCode::kFailedPrecondition, "SFCSAMPLER_LIB_DIR");
    EXPECT_LE(status.message().size(), 1024u);
  }
  r.tree.surface = "torus";
  EXPECT_EQ(DrawAll(engine, r).size(), 100u);
}

// The point of the CAD module: sampling formula surfaces maps none of
// OpenCASCADE's libraries; the first CAD model loads the module, which
// samples it.
TEST(ModuleKinds, OpenCascadeIsLoadedOnlyForTheFirstModel) {
  const SurfaceKinds& kinds = RegisteredSurfaceKinds();
  if (!kinds.For(ModelSpec{ModelFormat::kNurbs, "x", ""})) GTEST_SKIP() << "a build without CAD";
  DirectTreeSource source;
  FileModelSource files;
  SamplingEngine engine(kinds, {}, &source, &files);
  SampleRequest r;
  r.count = 1000;
  EXPECT_EQ(DrawAll(engine, r).size(), 1000u);
  EXPECT_EQ(Mapped("libTKernel"), 0) << "a sphere loaded OpenCASCADE";
  EXPECT_EQ(Mapped("libsfcsampler-cad"), 0);
  r.tree.surface = "nurbs:" + WriteTemp("sheet.nurbs", kSheetNurbs);
  r.fields.face = true;
  const SampleBatch batch = DrawAll(engine, r);
  EXPECT_EQ(batch.size(), 1000u);
  EXPECT_EQ(batch.face.size(), 1000u);
  EXPECT_GT(Mapped("libTKernel"), 0);
  EXPECT_GT(Mapped("libsfcsampler-cad"), 0);
}

int Threads() {
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);) {
    if (line.rfind("Threads:", 0) == 0) return std::stoi(line.substr(8));
  }
  return -1;
}

// The module's cursors run on the program's worker pool (base/worker_pool.h:
// one pool a process), not on a second pool of their own copy's.
TEST(ModuleKinds, TheModuleSharesTheProgramsWorkerPool) {
  const SurfaceKinds& kinds = RegisteredSurfaceKinds();
  if (!kinds.For(ModelSpec{ModelFormat::kNurbs, "x", ""})) GTEST_SKIP() << "a build without CAD";
  DirectTreeSource source;
  FileModelSource files;
  EngineLimits limits;
  limits.generation_threads = 4;
  limits.model_parse_threads = 0;  // the model parsed on this thread: no parse thread either
  SamplingEngine engine(kinds, limits, &source, &files);
  WorkerPool::Shared();  // the program's pool, started
  const int threads = Threads();
  SampleRequest r;
  r.count = 400000;
  r.tree.surface = "nurbs:" + WriteTemp("pool.nurbs", kSheetNurbs);
  auto job = engine.Start(r);
  ASSERT_TRUE(job.ok()) << job.status();
  SampleBatch all;
  while (true) {  // in batches large enough to be filled in parallel
    auto n = job->cursor->Next(r.count, &all);
    ASSERT_TRUE(n.ok()) << n.status();
    if (*n == 0) break;
  }
  EXPECT_EQ(all.size(), r.count);
  EXPECT_EQ(Threads(), threads) << "the CAD module started threads of its own";
}

}  // namespace
}  // namespace sfc
