// sfcsampler._core.Engine and Job: the embedded sampler. An Engine is the
// CLI's SamplingEngine (engine/sampling_engine.h) over an in-process tree
// source; a Job is one request's cursor, filling NumPy arrays batch by batch.
// The C++ work (tree build, sample generation, float32 narrowing) runs with
// the GIL released, and the filled vectors become the arrays' buffers
// without a copy (python/bindings/arrays.h).
//
// Thread-safety: an Engine may be used from several Python threads at once
// (its tree source is locked); a Job serialises calls to next().
#include <algorithm>
#include <memory>
#include <mutex>
#include <thread>

#include "core/curve.h"
#include "core/vector_math.h"
#include "engine/sampling_engine.h"
#include "kinds/registered_kinds.h"
#include "pybind11/numpy.h"
#include "python/bindings/batch_columns.h"
#include "python/bindings/buffer_pool.h"
#include "python/bindings/errors.h"
#include "python/bindings/memory_models.h"
#include "python/bindings/mesh_arrays.h"
#include "python/bindings/recent_tree_source.h"
#include "python/bindings/register.h"
#include "python/bindings/request.h"
#include "python/bindings/tree_summary_dict.h"
#include "request/model_spec.h"
#include "request/request_flags.h"
#include "request/stream_options.h"
#include "request/tree_count.h"

namespace py = pybind11;

namespace sfc::python {

namespace {

// Fills `filled` with up to `max_samples` more of `job`'s samples, of which
// `produced` came before; narrows them to float32 when asked. Returns how
// many it gave. Needs no GIL.
uint64_t Fill(SamplingJob& job, const SampleFields& fields, bool region, bool float32,
              uint64_t produced, uint64_t max_samples, BufferPool* pool, BatchColumns* filled) {
  SampleBatch& batch = filled->batch;
  // Reserve what a plain range will produce, so filling never reallocates.
  const uint64_t left = job.end - job.begin - std::min(job.end - job.begin, produced);
  const size_t reserve =
      static_cast<size_t>(std::min(max_samples, region ? uint64_t{1} << 16 : left));
  TakeColumns(fields, reserve, *pool, &batch);
  uint64_t got = 0;
  while (got < max_samples) {
    // A region may drop samples, so ask for what is still wanted.
    auto n = job.cursor->Next(static_cast<size_t>(max_samples - got), &batch);
    ThrowIfError(n.status());
    if (*n == 0) break;
    got += *n;
  }
  if (float32) Narrow(filled, pool);
  return got;
}

class PyJob {
 public:
  PyJob(SamplingJob job, const SampleRequest& request, bool float32,
        std::shared_ptr<BufferPool> pool)
      : job_(std::move(job)),
        pool_(std::move(pool)),
        fields_(request.fields),
        float32_(float32),
        seed_(request.seed),
        region_(request.region.kind != Region::Kind::kAll) {}

  // Up to `max_samples` more samples as a dict of columns, or None once the
  // job is exhausted.
  py::object Next(uint64_t max_samples) {
    if (max_samples == 0) {
      throw StatusException(absl::InvalidArgumentError("max_samples must be >= 1"));
    }
    BatchColumns filled;
    {
      py::gil_scoped_release release;
      std::lock_guard<std::mutex> lock(mu_);
      produced_ +=
          Fill(job_, fields_, region_, float32_, produced_, max_samples, pool_.get(), &filled);
    }
    if (filled.batch.size() == 0) return py::none();
    return ColumnsDict(std::move(filled), fields_, pool_);
  }

  py::dict Tree() const { return TreeSummaryDict(SummarizeTree(job_.tree)); }
  uint64_t begin() const { return job_.begin; }
  uint64_t end() const { return job_.end; }
  py::object Expected() const {
    if (region_) return py::none();
    return py::int_(job_.end - job_.begin);
  }
  uint64_t seed() const { return seed_; }

 private:
  std::mutex mu_;
  SamplingJob job_;
  const std::shared_ptr<BufferPool> pool_;
  const SampleFields fields_;
  const bool float32_;
  const uint64_t seed_;
  const bool region_;
  uint64_t produced_ = 0;
};

class PyEngine {
 public:
  PyEngine(size_t max_trees, int threads, const std::string& model_check_program,
           double model_parse_seconds, uint64_t parsed_model_bytes, int parse_threads,
           uint64_t output_pool_bytes)
      : source_(max_trees),
        pool_(std::make_shared<BufferPool>(output_pool_bytes)),
        engine_(RegisteredSurfaceKinds(),
                Limits(threads, model_check_program, model_parse_seconds, parsed_model_bytes,
                       parse_threads),
                &source_, &models_) {}

  std::string HoldModel(const std::string& format, const py::bytes& data, const std::string& name) {
    const auto parsed = ModelFormatFromName(format);
    if (!parsed) {
      throw StatusException(absl::InvalidArgumentError("model format must be " + ModelFormatList() +
                                                       ", not \"" + format + "\""));
    }
    std::string bytes = data;  // one copy, owned by the held model
    py::gil_scoped_release release;
    return models_.Hold(*parsed, std::move(bytes), name);
  }

  void ReleaseModel(const std::string& spec) { models_.Release(spec); }

  std::unique_ptr<PyJob> Start(const PyRequest& r, const std::string& precision) {
    const absl::StatusOr<ColumnPrecision> parsed = ParseColumnPrecision(precision);
    ThrowIfError(parsed.status());
    absl::StatusOr<SamplingJob> job;
    {
      py::gil_scoped_release release;
      job = engine_.Start(r.request, {}, *parsed);
    }
    ThrowIfError(job.status());
    return std::make_unique<PyJob>(*std::move(job), r.request, *parsed == ColumnPrecision::kFloat32,
                                   pool_);
  }

  // sample_mesh_arrays(): see its docstring below.
  py::object SampleMeshArrays(const py::array& vertices, const py::array& faces, const PyRequest& r,
                              uint64_t base_seed, const std::string& precision,
                              const std::string& name) {
    auto float64 = [](const py::array& a) {
      return a.dtype().kind() == 'f' && a.itemsize() == 8 && a.dtype().byteorder() != '>';
    };
    auto int32_or_64 = [](const py::array& a) {
      return a.dtype().kind() == 'i' && (a.itemsize() == 4 || a.itemsize() == 8) &&
             a.dtype().byteorder() != '>';
    };
    auto rows_of_three = [](const py::array& a) {
      return a.ndim() == 2 && a.shape(1) == 3 && (a.flags() & py::array::c_style) != 0;
    };
    if (!float64(vertices) || !int32_or_64(faces) || !rows_of_three(vertices) ||
        !rows_of_three(faces)) {
      return py::none();
    }
    const absl::StatusOr<ColumnPrecision> parsed = ParseColumnPrecision(precision);
    ThrowIfError(parsed.status());
    const bool float32 = *parsed == ColumnPrecision::kFloat32;
    const auto* v = static_cast<const double*>(vertices.data());
    const void* f = faces.data();
    const auto vertex_count = static_cast<size_t>(vertices.shape(0));
    const auto face_count = static_cast<size_t>(faces.shape(0));
    const bool wide = faces.itemsize() == 8;
    std::string sha256;
    uint64_t seed = 0;
    absl::StatusOr<SamplingJob> job;
    SampleRequest request;
    BatchColumns filled;
    {
      // The arrays stay alive (the caller holds them) and are only read.
      py::gil_scoped_release release;
      std::string ply;
      if (!CanonicalPly(v, vertex_count, nullptr, nullptr, f, wide, face_count, &ply)) {
        ply.clear();
      } else {
        const std::string spec = models_.Hold(ModelFormat::kPly, std::move(ply), name);
        struct Release {
          MemoryModelSource& models;
          const std::string& spec;
          ~Release() { models.Release(spec); }
        } release_hold{models_, spec};
        sha256 = spec.substr(spec.rfind('=') + 1);
        seed = ModelSeed(base_seed, sha256);
        RequestFlags flags = r.flags;
        flags.surface = spec;
        flags.seed = seed;
        absl::StatusOr<SampleRequest> parsed_request = ToSampleRequest(flags);
        if (!parsed_request.ok()) {
          job = parsed_request.status();
        } else {
          request = *std::move(parsed_request);
          job = engine_.Start(request, {}, *parsed);
          if (job.ok()) {
            Fill(*job, request.fields, request.region.kind != Region::Kind::kAll, float32, 0,
                 uint64_t{1} << 62, pool_.get(), &filled);
          }
        }
      }
    }
    if (sha256.empty()) return py::none();  // a check failed: canonical_ply() names it
    ThrowIfError(job.status());
    py::object columns = filled.batch.size() == 0
                             ? py::object(py::dict())
                             : py::object(ColumnsDict(std::move(filled), request.fields, pool_));
    return py::make_tuple(sha256, seed, columns, TreeSummaryDict(SummarizeTree(job->tree)),
                          job->begin, job->end);
  }

  py::dict Prepare(const PyRequest& r) {
    absl::StatusOr<PreparedTree> tree;
    {
      py::gil_scoped_release release;
      const absl::StatusOr<uint64_t> tree_count = ResolveTreeCount(r.request);
      tree = tree_count.ok() ? engine_.Prepare(r.request.tree, *tree_count)
                             : absl::StatusOr<PreparedTree>(tree_count.status());
    }
    ThrowIfError(tree.status());
    return TreeSummaryDict(SummarizeTree(*tree));
  }

 private:
  // The CLI's embedded limits (client/cli/in_process_sample_source.cc): the server's
  // defaults, with up to four generation threads.
  static EngineLimits Limits(int threads, const std::string& model_check_program,
                             double model_parse_seconds, uint64_t parsed_model_bytes,
                             int parse_threads) {
    if (model_parse_seconds < 0) {
      throw StatusException(absl::InvalidArgumentError("model_parse_seconds must be >= 0"));
    }
    if (parse_threads < 0 || parse_threads > 64) {
      throw StatusException(absl::InvalidArgumentError("parse_threads must be in [0, 64]"));
    }
    EngineLimits limits;
    limits.model_check_program = model_check_program;
    limits.model_parse_seconds = model_parse_seconds;
    limits.parsed_model_bytes = parsed_model_bytes;
    limits.model_parse_threads = parse_threads;
    // Calls that share the engine may all wait for a parse at once.
    limits.max_queued_parses = std::max(limits.max_queued_parses, 2 * parse_threads);
    limits.generation_threads =
        threads > 0
            ? threads
            : static_cast<int>(std::max(1u, std::min(4u, std::thread::hardware_concurrency())));
    return limits;
  }

  RecentTreeSource source_;
  const std::shared_ptr<BufferPool> pool_;  // the arrays' buffers, for the next calls
  MemoryModelSource models_;                // local files, and meshes handed over as arrays
  SamplingEngine engine_;
};

}  // namespace

void RegisterSampling(py::module_& m) {
  m.attr("ALGORITHM_VERSION") = kAlgorithmVersion;
  // The vector path the elementary functions take here (never changes the bytes).
  m.attr("VECTOR_PATH") = std::string(math::VectorPathName(math::BestVectorPath()));

  py::class_<PyJob>(m, "Job", "One request's samples, in curve order; made by Engine.start().")
      .def("next", &PyJob::Next, py::arg("max_samples"),
           "Up to max_samples more samples as a dict of NumPy arrays (index: uint64; u, v, x, y, "
           "z and the requested optional columns: float64, or float32 when asked), or None once "
           "the set is exhausted. The GIL is released while the arrays are filled.")
      .def_property_readonly("tree", &PyJob::Tree,
                             "the curve tree's summary (the wire's TreeInfo fields)")
      .def_property_readonly("begin", &PyJob::begin, "first index of the resolved range")
      .def_property_readonly("end", &PyJob::end, "one past the last index of the resolved range")
      .def_property_readonly("expected_samples", &PyJob::Expected,
                             "how many samples the job yields; None for a region request")
      .def_property_readonly("seed", &PyJob::seed);

  py::class_<PyEngine>(m, "Engine", R"doc(
The embedded sampler: the same engine as `sfcsampler sample` without --server.

max_trees: keep the curve trees of the last this many (surface, density,
  options, grade) combinations, so repeated requests skip the build (0 = build
  every time, as the CLI does).
threads: threads filling one request's samples (0 = as the CLI: up to 4). The
  samples do not depend on it.
model_check_program: a program (sfcsampler-model-check) that reads each CAD
  file in a process of its own, so a file that crashes or loops the CAD kernel,
  or leaves it broken for the next file, fails alone; "" = read in this process.
model_parse_seconds: CPU seconds one model's parse may take (0 = no limit).
parsed_model_bytes: parsed models (meshes, CAD shapes) kept for later calls, in
  bytes, least recently used out first (0 = none: each call parses its model,
  as a run over many models seen once wants).
parse_threads: 0 = each call parses its model on its own thread (no hand-over
  to another thread); 1 to 64 = models parsed at once on the engine's threads.
output_pool_bytes: buffers of freed result arrays (1 MiB or more each) kept, in
  bytes, to hold later results: a warm loop refills memory it owns instead of
  the kernel faulting in fresh pages (0 = none).)doc")
      .def(py::init<size_t, int, const std::string&, double, uint64_t, int, uint64_t>(),
           py::kw_only(), py::arg("max_trees") = 0, py::arg("threads") = 0,
           py::arg("model_check_program") = "", py::arg("model_parse_seconds") = 0.0,
           py::arg("parsed_model_bytes") = EngineLimits().parsed_model_bytes,
           py::arg("parse_threads") = 0, py::arg("output_pool_bytes") = 0)
      .def("start", &PyEngine::Start, py::arg("request"), py::kw_only(),
           py::arg("precision") = "float64",
           "Validates the request, builds (or reuses) its tree and opens its job. Raises "
           "sfcsampler.InvalidArgumentError or ResourceExhaustedError with the engine's message.")
      .def("hold_model", &PyEngine::HoldModel, py::arg("format"), py::arg("data"),
           py::arg("name") = "",
           "Holds a model's file bytes (FORMAT step, iges, nurbs, obj or ply) in memory, hashes "
           "them (SHA-256, GIL released) and returns the spec \"FORMAT:sha256=<hex>\" that "
           "requests name it by until release_model(spec). Holds are counted.")
      .def("release_model", &PyEngine::ReleaseModel, py::arg("spec"),
           "Ends one hold_model() of `spec`; the bytes go when the last hold ends.")
      .def("sample_mesh_arrays", &PyEngine::SampleMeshArrays, py::arg("vertices"), py::arg("faces"),
           py::arg("request"), py::kw_only(), py::arg("base_seed"),
           py::arg("precision") = "float64", py::arg("name") = "",
           "One mesh of a many-model run, all of it with the GIL released: the canonical PLY "
           "of (vertices, faces) (float64 and int32/int64 C-contiguous (n, 3) arrays; "
           "meshes.canonical_ply's bytes), its SHA-256, its seed model_seed(base_seed, sha256), "
           "and every sample of `request` (a Request on any surface and seed, which the mesh "
           "and its seed replace). Returns (sha256, seed, columns, tree, begin, end), exactly "
           "what holding the PLY and sampling it gives; None when the arrays are of another "
           "kind or fail a check of canonical_ply(), which then names the error.")
      .def("prepare", &PyEngine::Prepare, py::arg("request"),
           "Builds (or reuses) the request's tree, sized for tree_count (or count), and returns "
           "its summary.");
}

}  // namespace sfc::python
