// sfcsampler: the command-line interface. Without --server every subcommand
// runs the sampler in-process (the embedded default).
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <set>
#include <thread>

#include "CLI/CLI.hpp"
#include "absl/strings/str_format.h"
#include "base/status_macros.h"
#include "catalog/catalog.h"
#include "client/cli/eval_quality.h"
#include "client/cli/progress.h"
#include "client/cli/request_flags.h"
#include "client/cli/sample_many.h"
#include "client/sample_writer.h"
#include "client/sampler_client.h"
#include "core/area_estimator.h"
#include "core/curve.h"
#include "core/sequence.h"
#include "engine/model_source.h"
#include "engine/sampling_engine.h"
#include "evaluation/discrepancy.h"
#include "evaluation/plot.h"
#include "evaluation/protocol.h"
#include "kinds/registered_kinds.h"
#include "render/render.h"
#include "proto/convert.h"
#include "proto/service_convert.h"

namespace sfc {
namespace {

int Fail(const absl::Status& status) {
  std::fprintf(stderr, "sfcsampler: %s: %s\n", absl::StatusCodeToString(status.code()).c_str(),
               std::string(status.message()).c_str());
  return status.code() == absl::StatusCode::kInvalidArgument ? 2 : 1;
}

// Where to run: in-process (server empty) or over the wire.
struct Connection {
  std::string server;      // host:port; "" = embedded
  std::string token_file;  // bearer token
  bool tls = false;
  std::string tls_roots;
  std::string tls_cert, tls_key;  // client certificate for mutual TLS
};

absl::StatusOr<std::unique_ptr<SamplerClient>> Connect(
    const Connection& c, uint32_t batch_size,
    v1::Precision precision = v1::PRECISION_FLOAT64) {
  ClientOptions options;
  options.precision = precision;
  options.target = c.server;
  options.tls = c.tls || !c.tls_roots.empty() || !c.tls_cert.empty();
  options.tls_root_certs_file = c.tls_roots;
  options.tls_cert_file = c.tls_cert;
  options.tls_key_file = c.tls_key;
  options.batch_size = batch_size;
  if (!c.token_file.empty()) {
    std::FILE* f = std::fopen(c.token_file.c_str(), "r");
    if (!f) return absl::InvalidArgumentError("cannot read --token-file " + c.token_file);
    char buf[4096];
    const size_t n = std::fread(buf, 1, sizeof(buf), f);
    std::fclose(f);
    options.token = std::string(buf, n);
    while (!options.token.empty() && std::isspace(static_cast<unsigned char>(options.token.back()))) {
      options.token.pop_back();
    }
  }
  return SamplerClient::Connect(options);
}

// What `sample` prints on stderr: -q drops the summary, the progress lines
// and the note on fitted power laws, --no-warnings the warnings too (which
// -q keeps: they say the samples' density is only approximate somewhere).
struct Verbosity {
  bool quiet = false;
  bool no_warnings = false;
};

// The tree summary and the depth-cap warnings, on stderr; the same for the
// embedded mode (converted with ToProto) and the wire.
void PrintTreeInfo(const ::sfcsampler::v1::TreeInfo& t, const Verbosity& verbosity = {}) {
  if (!verbosity.quiet && (t.kind() == "mesh" || t.kind() == "model")) {
    std::fprintf(stderr, "%s tree %s (%s): %llu leaves, %llu bytes\n", t.kind().c_str(),
                 t.key_with_grade().c_str(),
                 t.cache_hit() ? "cache hit" : "built", static_cast<unsigned long long>(t.leaves()),
                 static_cast<unsigned long long>(t.bytes()));
    return;
  }
  if (!verbosity.quiet) {
    std::fprintf(stderr, "tree %s (%s): %llu leaves, depth %d..%d, %llu bytes, tolerance %.6g\n",
                 t.key_with_grade().c_str(),
                 t.cache_hit() ? "cache hit" : t.refined() ? "refined from cache" : "built",
                 static_cast<unsigned long long>(t.leaves()), t.min_depth(), t.max_depth(),
                 static_cast<unsigned long long>(t.bytes()), t.tolerance());
    std::fprintf(stderr, "precision: model error %.3g samples in all (%.3g where the tests wanted more) at N = 2^%d\n",
                 t.error_samples(), t.unresolved_error_samples(), t.grade());
  }
  if (verbosity.no_warnings) return;
  // A note, not a warning: the power laws follow the mass (-q drops it).
  if (t.warped_leaves() > 0 && !verbosity.quiet) {
    std::fprintf(stderr,
                 "note: the parameterisation is singular (the area element blows up or vanishes on "
                 "parameter lines, paper Sect. 5.3); %llu leaves beside those lines follow a fitted "
                 "power law%s\n",
                 static_cast<unsigned long long>(t.warped_leaves()),
                 t.singular_leaves() > 0 ? "" : ". Finest:");
    if (t.singular_leaves() == 0) {
      for (const auto& w : t.singular()) {
        std::fprintf(stderr, "  cell u in [%.9g, %.9g], v in [%.9g, %.9g]\n", w.u0(),
                     w.u0() + w.size(), w.v0(), w.v0() + w.size());
      }
    }
  }
  if (t.singular_leaves() > 0) {
    std::fprintf(stderr,
                 "warning: the parameterisation is singular (the area element blows up, paper Sect. "
                 "5.3) in %llu leaves that no edge power law fits; their masses come from mapped "
                 "sub-triangles and samples are spread evenly inside their sub-squares. Finest:\n",
                 static_cast<unsigned long long>(t.singular_leaves()));
    for (const auto& w : t.singular()) {
      std::fprintf(stderr, "  cell u in [%.9g, %.9g], v in [%.9g, %.9g]\n", w.u0(), w.u0() + w.size(),
                   w.v0(), w.v0() + w.size());
    }
  }
  if (t.flatness_capped_leaves() || t.mass_capped_leaves()) {
    std::fprintf(stderr,
                 "warning: the depth cap stopped splits the tests still wanted (paper Sect. 5.3): "
                 "%llu leaves for flatness, %llu for mass\n",
                 static_cast<unsigned long long>(t.flatness_capped_leaves()),
                 static_cast<unsigned long long>(t.mass_capped_leaves()));
    for (const auto& w : t.warnings()) {
      std::fprintf(stderr,
                   "  %s test at cell u in [%.9g, %.9g], v in [%.9g, %.9g]: %.6g vs limit %.6g (x%.3g)\n",
                   w.test().c_str(), w.u0(), w.u0() + w.size(), w.v0(), w.v0() + w.size(),
                   w.measured(), w.limit(), w.measured() / w.limit());
    }
  }
}

// Model specs in process name local files.
const FileModelSource& LocalModels() {
  static const FileModelSource* const files = new FileModelSource();
  return *files;
}

void PrintTree(const PreparedTree& tree, double seconds, const Verbosity& verbosity = {}) {
  ::sfcsampler::v1::TreeInfo info;
  ToProto(tree, &info);
  PrintTreeInfo(info, verbosity);
  if (!verbosity.quiet) std::fprintf(stderr, "tree ready in %.3f s\n", seconds);
}

struct OutputFlags {
  std::string format = "csv";
  bool ascii = false;
  std::string output = "-";
  size_t batch_size = 0;  // 0: 65536 in-process, the server's choice over the wire
  std::string precision = "float64";
};

// Every sample of `request`, in curve order, from the server or in-process,
// to `on_batch`. The tree summary goes to stderr per `verbosity`; `progress`
// shows the build and the stream. Used by `sample` and `render`.
absl::Status StreamSamples(const SampleRequest& request, const Connection& conn, size_t batch_size,
                           v1::Precision precision, const Verbosity& verbosity, Progress* progress,
                           const std::function<absl::Status(std::optional<uint64_t> expected,
                                                            const SampleBatch&)>& on_batch,
                           std::string* provenance) {
  const auto start = std::chrono::steady_clock::now();
  if (!conn.server.empty()) {
    ASSIGN_OR_RETURN(auto client, Connect(conn, static_cast<uint32_t>(batch_size), precision));
    uint64_t done = 0;
    progress->StartPhase("waiting for " + conn.server + " (it may be building the curve tree)");
    ASSIGN_OR_RETURN(
        const StreamSummary summary,
        client->Sample(request, [&](const ::sfcsampler::v1::StreamHeader& header, const SampleBatch& batch) {
          if (done == 0) {
            progress->EndPhase();
            PrintTreeInfo(header.tree(), verbosity);
          }
          std::optional<uint64_t> expected;
          if (header.expected_samples() >= 0) expected = header.expected_samples();
          done += batch.size();
          progress->Samples(done, expected.value_or(0));
          return on_batch(expected, batch);
        }));
    progress->Done();
    *provenance = absl::StrFormat("from %s (%s, seed %d, %d resumes)", conn.server,
                                  summary.header.algorithm_version(), request.seed, summary.resumes);
    return absl::OkStatus();
  }
  DirectTreeSource source;
  EngineLimits limits;
  limits.generation_threads = std::max(1u, std::min(4u, std::thread::hardware_concurrency()));
  SamplingEngine engine(RegisteredSurfaceKinds(), limits, &source, &LocalModels());
  progress->StartPhase("building the curve tree");
  auto job = engine.Start(request);
  progress->EndPhase();
  RETURN_IF_ERROR(job.status());
  PrintTree(job->tree, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(),
            verbosity);
  std::optional<uint64_t> expected;
  if (request.region.kind == Region::Kind::kAll) expected = job->end - job->begin;
  SampleBatch batch;
  uint64_t done = 0;
  while (true) {
    batch.Clear();
    ASSIGN_OR_RETURN(const size_t n, job->cursor->Next(batch_size == 0 ? 65536 : batch_size, &batch));
    if (n == 0) break;
    RETURN_IF_ERROR(on_batch(expected, batch));
    done += n;
    progress->Samples(done, expected.value_or(0));
  }
  progress->Done();
  *provenance = absl::StrFormat("(%s, seed %d)", kAlgorithmVersion, request.seed);
  return absl::OkStatus();
}

absl::StatusOr<OutputPrecision> ParsePrecision(const std::string& text) {
  if (text == "float64") return OutputPrecision::kFloat64;
  if (text == "float32") return OutputPrecision::kFloat32;
  return absl::InvalidArgumentError("--precision must be float64 or float32");
}

int RunSample(const RequestFlags& flags, const OutputFlags& out, const Verbosity& verbosity,
              const Connection& conn) {
  auto request = ToSampleRequest(flags);
  if (!request.ok()) return Fail(request.status());
  OutputFormat out_format;
  if (out.format == "csv") {
    out_format = OutputFormat::kCsv;
  } else if (out.format == "ply") {
    out_format = out.ascii ? OutputFormat::kPlyAscii : OutputFormat::kPlyBinary;
  } else if (out.format == "npy") {
    out_format = OutputFormat::kNpy;
  } else {
    return Fail(absl::InvalidArgumentError("--format must be csv, ply or npy"));
  }
  auto precision = ParsePrecision(out.precision);
  if (!precision.ok()) return Fail(precision.status());
  const auto start = std::chrono::steady_clock::now();
  std::unique_ptr<SampleWriter> writer;
  Progress progress(!verbosity.quiet);
  std::string provenance;
  // Float32 output asks the server for float32 columns: half the bytes, and
  // the same file (the writer rounds doubles to floats the same way).
  absl::Status status = StreamSamples(
      *request, conn, out.batch_size,
      *precision == OutputPrecision::kFloat32 ? v1::PRECISION_FLOAT32 : v1::PRECISION_FLOAT64,
      verbosity, &progress,
      [&](std::optional<uint64_t> expected, const SampleBatch& batch) {
        if (!writer) {
          ASSIGN_OR_RETURN(writer, SampleWriter::Open(out.output, out_format, request->fields,
                                                      expected, *precision));
        }
        return writer->Write(batch);
      },
      &provenance);
  if (!status.ok()) return Fail(status);
  if (!writer) {  // a region with no samples: still write a valid, empty file
    auto opened = SampleWriter::Open(out.output, out_format, request->fields, std::nullopt, *precision);
    if (!opened.ok()) return Fail(opened.status());
    writer = *std::move(opened);
  }
  if (auto s = writer->Finish(); !s.ok()) return Fail(s);
  if (!verbosity.quiet) {
    std::fprintf(stderr, "%llu samples written to %s in %.3f s %s\n",
                 static_cast<unsigned long long>(writer->written()), out.output.c_str(),
                 std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(),
                 provenance.c_str());
  }
  return 0;
}

int RunPrepare(const RequestFlags& flags, const Connection& conn) {
  auto spec = ToTreeSpec(flags);
  if (!spec.ok()) return Fail(spec.status());
  if (!conn.server.empty()) {
    auto client = Connect(conn, 0);
    if (!client.ok()) return Fail(client.status());
    Progress progress(true);
    progress.StartPhase("waiting for " + conn.server + " to prepare the curve tree");
    auto response = (*client)->Prepare(*spec, flags.tree_count ? flags.tree_count : flags.count);
    progress.Done();
    if (!response.ok()) return Fail(response.status());
    PrintTreeInfo(response->tree());
    std::fprintf(stderr, "prepared in %.3f s\n", response->seconds());
    std::printf("%s\n", response->tree().key_with_grade().c_str());
    return 0;
  }
  DirectTreeSource source;
  SamplingEngine engine(RegisteredSurfaceKinds(), EngineLimits{}, &source, &LocalModels());
  const auto start = std::chrono::steady_clock::now();
  Progress progress(true);
  progress.StartPhase("building the curve tree");
  auto prepared = engine.Prepare(*spec, flags.tree_count ? flags.tree_count : flags.count);
  progress.Done();
  if (!prepared.ok()) return Fail(prepared.status());
  PrintTree(*prepared, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  std::printf("%s\n", prepared->key.HexWithGrade(prepared->grade).c_str());
  return 0;
}

void PrintCatalog(const char* title, const std::vector<CatalogEntry>& entries) {
  std::printf("%s\n", title);
  for (const CatalogEntry& e : entries) {
    std::printf("  %-15s %s\n  %-15s   %s\n", e.name.c_str(), e.description.c_str(), "",
                e.formula.c_str());
    for (const CatalogParameter& p : e.parameters) {
      std::printf("  %-15s   %s=%s  %s\n", "", p.name.c_str(),
                  p.default_value.empty() ? "(required)" : p.default_value.c_str(), p.meaning.c_str());
    }
  }
}

int RunCache(const Connection& conn) {
  if (conn.server.empty()) {
    return Fail(absl::FailedPreconditionError("cache statistics need --server HOST:PORT"));
  }
  auto client = Connect(conn, 0);
  if (!client.ok()) return Fail(client.status());
  auto stats = (*client)->GetCacheStats();
  if (!stats.ok()) return Fail(stats.status());
  std::printf("%s", stats->DebugString().c_str());
  return 0;
}

int RunHealth(const Connection& conn) {
  if (conn.server.empty()) return Fail(absl::FailedPreconditionError("health needs --server HOST:PORT"));
  auto client = Connect(conn, 0);
  if (!client.ok()) return Fail(client.status());
  auto serving = (*client)->CheckHealth();
  if (!serving.ok()) return Fail(serving.status());
  std::printf("%s\n", *serving ? "SERVING" : "NOT_SERVING");
  return *serving ? 0 : 1;
}

// Uploads model files the server lacks and prints their wire specs, one a line.
int RunUpload(const std::vector<std::string>& specs, const Connection& conn) {
  if (conn.server.empty()) return Fail(absl::FailedPreconditionError("upload needs --server HOST:PORT"));
  auto client = Connect(conn, 0);
  if (!client.ok()) return Fail(client.status());
  for (const std::string& spec : specs) {
    auto parsed = ParseModelSpec(spec);
    if (!parsed.ok()) return Fail(parsed.status());
    if (!parsed->has_value()) {
      return Fail(absl::InvalidArgumentError(absl::StrFormat(
          "\"%s\" names no model file; write FORMAT:FILE with FORMAT step, iges, nurbs, obj or ply",
          spec)));
    }
    auto wire = (*client)->EnsureModel(spec);
    if (!wire.ok()) return Fail(wire.status());
    std::printf("%s\n", wire->c_str());
  }
  return 0;
}

// The faces of CAD models, read in process (the file is on this machine).
int RunInspect(const std::vector<std::string>& specs) {
  DirectTreeSource source;
  SamplingEngine engine(RegisteredSurfaceKinds(), EngineLimits{}, &source, &LocalModels());
  for (const std::string& spec : specs) {
    auto table = engine.DescribeModel(spec);
    if (!table.ok()) return Fail(table.status());
    std::printf("%s", table->c_str());
  }
  return 0;
}

struct EvalFlags {
  std::string setting = "fast";
  int l_min = 0, l_max = 0;
  std::vector<std::string> plane, sphere;
  std::string out_dir = "eval-out";
  uint64_t seed = 1;
  std::string model;  // model mode: a sphere-shaped model spec against the built-in sphere
  int seeds = 2;
  EvalQualityFlags quality;
};

// The whole jittered set of `count` samples (seed `seed`) of the surface and
// density, in curve order, from the server or in process.
absl::StatusOr<SampleBatch> WholeSet(const Connection& conn, const std::string& surface,
                                     const std::string& density, uint64_t count, uint64_t seed) {
  SampleRequest request;
  request.tree.surface = surface;
  request.tree.density = density;
  request.count = count;
  request.seed = seed;
  SampleBatch all;
  Progress quiet(false);
  std::string provenance;
  RETURN_IF_ERROR(StreamSamples(
      request, conn, 0, v1::PRECISION_FLOAT64, Verbosity{true, true}, &quiet,
      [&](std::optional<uint64_t>, const SampleBatch& batch) {
        all.Append(batch);
        return absl::OkStatus();
      },
      &provenance));
  return all;
}

// Model mode (issue 11): the spherical-triangle discrepancy of a model that is
// a sphere (a STEP, IGES or NURBS sphere, or a mesh of one) against the
// built-in sphere, N = 64 .. 24576, the mean over `seeds` seeds, and both
// slopes. Points are projected onto the unit sphere about the centre of their
// bounding box; the model's own deviation from a sphere shows as
// discrepancy. Sets come from the server with --server.
int RunEvalModel(const EvalFlags& f, const Connection& conn) {
  auto discrepancy = [&](const std::string& surface, uint64_t n,
                         uint64_t seed) -> absl::StatusOr<double> {
    ASSIGN_OR_RETURN(const SampleBatch all, WholeSet(conn, surface, "uniform", n, seed));
    Vec3 lo{INFINITY, INFINITY, INFINITY}, hi{-INFINITY, -INFINITY, -INFINITY};
    for (size_t i = 0; i < all.size(); ++i) {
      lo = {std::min(lo.x, all.x[i]), std::min(lo.y, all.y[i]), std::min(lo.z, all.z[i])};
      hi = {std::max(hi.x, all.x[i]), std::max(hi.y, all.y[i]), std::max(hi.z, all.z[i])};
    }
    const Vec3 centre = (lo + hi) * 0.5;
    std::vector<Vec3> points;
    for (size_t i = 0; i < all.size(); ++i) {
      const Vec3 d = Vec3{all.x[i], all.y[i], all.z[i]} - centre;
      points.push_back(d * (1 / Norm(d)));
    }
    return SphericalTriangleDiscrepancy(points);
  };
  std::vector<double> ns, model_d, sphere_d;
  std::printf("spherical-triangle discrepancy, mean of %d seeds\n\n| N | %s | built-in sphere |\n"
              "|---:|---:|---:|\n",
              f.seeds, f.model.c_str());
  for (int l = 6; l <= 14; ++l) {
    for (uint64_t n : {uint64_t{1} << l, (uint64_t{3} << l) / 2}) {
      if (n > 24576) continue;
      double dm = 0, ds = 0;
      for (int i = 0; i < f.seeds; ++i) {
        auto m = discrepancy(f.model, n, f.seed + i);
        if (!m.ok()) return Fail(m.status());
        auto b = discrepancy("sphere", n, f.seed + i);
        if (!b.ok()) return Fail(b.status());
        dm += *m / f.seeds, ds += *b / f.seeds;
      }
      ns.push_back(n), model_d.push_back(dm), sphere_d.push_back(ds);
      std::printf("| %llu | %.4g | %.4g |\n", static_cast<unsigned long long>(n), dm, ds);
    }
  }
  std::printf("| slope | **%.3f** | %.3f |\n", LogLogSlope(ns, model_d), LogLogSlope(ns, sphere_d));
  return 0;
}

int RunEval(const EvalFlags& f, const Connection& conn) {
  if (!f.model.empty()) return RunEvalModel(f, conn);
  if (f.setting != "fast" && f.setting != "full") {
    return Fail(absl::InvalidArgumentError("--setting must be fast or full"));
  }
  if (WantsSection(f.quality, "quality")) {
    // Every set of the report in full, from the server or in process.
    auto source = [&conn](const std::string& surface, const std::string& density, uint64_t count,
                          uint64_t seed) { return WholeSet(conn, surface, density, count, seed); };
    if (const int rc = RunEvalQuality(f.quality, f.setting == "full", f.out_dir, source); rc != 0) return rc;
  }
  if (!WantsSection(f.quality, "protocol")) return 0;
  ProtocolOptions options;
  std::unique_ptr<SamplerClient> client;
  if (!conn.server.empty()) {
    // Our point sets come from the server; the reference sets and the
    // discrepancies are computed here. The trees are the same, so are the sets.
    auto connected = Connect(conn, 0);
    if (!connected.ok()) return Fail(connected.status());
    client = *std::move(connected);
    options.our_sets = [&client](const std::string& surface, const std::string& density,
                                 const CurveTreeOptions& tree_options, uint64_t count,
                                 uint64_t seed) -> absl::StatusOr<SampleBatch> {
      SampleRequest request;
      request.tree.surface = surface;
      request.tree.density = density;
      request.tree.options = tree_options;
      request.sequence = SequenceKind::kJittered;
      request.count = count;
      request.seed = seed;
      SampleBatch all;
      RETURN_IF_ERROR(client->Sample(request, [&all](const ::sfcsampler::v1::StreamHeader&,
                                                     const SampleBatch& batch) {
        all.Append(batch);
        return absl::OkStatus();
      }).status());
      return all;
    };
  }
  if (f.setting == "full") {
    options.l_max = 20;  // the paper: 40 sizes, 2 to 2^20 + 2^19 = 1572864
  } else if (f.setting != "fast") {
    return Fail(absl::InvalidArgumentError("--setting must be fast or full"));
  }
  if (f.l_min) options.l_min = f.l_min;
  if (f.l_max) options.l_max = f.l_max;
  options.plane_methods = f.plane;
  options.sphere_methods = f.sphere;
  options.seed = f.seed;
  const auto start = std::chrono::steady_clock::now();
  const bool tty = isatty(STDERR_FILENO);
  auto rows = RunProtocol(options, [&](int done, int total) {
    // On a terminal a live counter; in a log a line every tenth.
    if (!tty && done % std::max(1, total / 10) != 0 && done != total) return;
    std::fprintf(stderr, tty ? "\reval: %d / %d point sets, %.0f s" : "eval: %d / %d point sets, %.0f s\n",
                 done, total, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  });
  std::fprintf(stderr, "\n");
  if (!rows.ok()) return Fail(rows.status());
  const std::string tables = SlopeTables(Slopes(*rows));
  std::printf("N = 2^l and 2^l + 2^(l-1), l = %d..%d, seed %llu\n\n%s", options.l_min,
              options.l_max, static_cast<unsigned long long>(options.seed), tables.c_str());
  std::error_code mkdir_error;
  std::filesystem::create_directories(f.out_dir, mkdir_error);
  if (mkdir_error) {
    return Fail(absl::UnavailableError(
        absl::StrFormat("cannot create the folder \"%s\": %s", f.out_dir, mkdir_error.message())));
  }
  auto write = [&](const std::string& name, const std::string& text) {
    std::FILE* out = std::fopen((f.out_dir + "/" + name).c_str(), "w");
    if (!out) return false;
    std::fputs(text.c_str(), out);
    return std::fclose(out) == 0;
  };
  if (!write("discrepancy.csv", RowsCsv(*rows)) || !write("slopes.md", tables)) {
    return Fail(absl::UnavailableError("cannot write into " + f.out_dir));
  }
  for (const char* measure : {"rectangular", "circular", "triangular"}) {
    if (auto st = PlotDiscrepancy(*rows, "plane", measure, f.out_dir + "/plane-" + measure); !st.ok()) return Fail(st);
  }
  if (auto st = PlotDiscrepancy(*rows, "sphere", "spherical", f.out_dir + "/sphere-spherical"); !st.ok()) {
    return Fail(st);
  }
  std::set<std::string> surfaces;
  for (const ProtocolRow& row : *rows) {
    if (row.density) surfaces.insert(row.domain);
  }
  for (const std::string& domain : surfaces) {
    std::string stem = domain.substr(8);  // after "surface "
    for (char& c : stem) {
      if (!std::isalnum(static_cast<unsigned char>(c))) c = '-';
    }
    if (auto st = PlotDiscrepancy(*rows, domain, "density", f.out_dir + "/surface-" + stem); !st.ok()) {
      return Fail(st);
    }
  }
  std::fprintf(stderr, "wrote %s/discrepancy.csv, slopes.md and plots (svg, png)\n", f.out_dir.c_str());
  return 0;
}

struct RenderFlags {
  std::string what = "samples";
  std::string view = "35,25";
  int size = 900;
  std::string title;
  std::string output = "render.png";
};

int RunRender(const RequestFlags& flags, const RenderFlags& r, const Connection& conn) {
  auto request = ToSampleRequest(flags);
  if (!request.ok()) return Fail(request.status());
  View view;
  view.width = view.height = r.size;
  view.title = r.title;
  if (std::sscanf(r.view.c_str(), "%lf,%lf", &view.azimuth_degrees, &view.elevation_degrees) != 2) {
    return Fail(absl::InvalidArgumentError("--view takes AZIMUTH,ELEVATION in degrees, e.g. 35,25"));
  }
  request->fields.normal = true;
  absl::Status status;
  if (r.what == "curve" || r.what == "param-curve") {
    if (!conn.server.empty()) {
      // The wire carries samples, not trees.
      return Fail(absl::FailedPreconditionError(
          "--what curve and param-curve draw the curve tree, which stays on the server; run them "
          "without --server (the tree is the same), or draw samples"));
    }
    DirectTreeSource source;
    SamplingEngine engine(RegisteredSurfaceKinds(), EngineLimits{}, &source, &LocalModels());
    auto job = engine.Start(*request);
    if (!job.ok()) return Fail(job.status());
    if (!job->tree.lookup.tree) {
      return Fail(absl::InvalidArgumentError(
          "--what curve and param-curve draw a parameter-square curve tree; a mesh has none: "
          "draw its samples (--what samples)"));
    }
    const CurveTree& tree = *job->tree.lookup.tree;
    const auto surface = MakeSurface(request->tree.surface);  // the surface its tree is over
    if (!surface.ok()) return Fail(surface.status());
    status = r.what == "curve" ? RenderCurve(tree, *surface->surface, view, r.output)
                               : RenderParameterCurve(tree, view, r.output);
    if (status.ok()) {
      std::fprintf(stderr, "wrote %s (%s, %zu leaves)\n", r.output.c_str(), r.what.c_str(), tree.leaf_count());
    }
  } else if (r.what == "samples" || r.what == "param-samples") {
    SampleBatch all;
    Progress progress(true);
    std::string provenance;
    status = StreamSamples(
        *request, conn, /*batch_size=*/0, v1::PRECISION_FLOAT64, Verbosity{true, false}, &progress,
        [&](std::optional<uint64_t>, const SampleBatch& batch) {
          all.Append(batch);
          return absl::OkStatus();
        },
        &provenance);
    if (!status.ok()) return Fail(status);
    status = r.what == "samples" ? RenderSamples(all, view, r.output)
                                 : RenderParameterSamples(all, view, r.output);
    if (status.ok()) {
      std::fprintf(stderr, "wrote %s (%s, %zu samples %s)\n", r.output.c_str(), r.what.c_str(), all.size(),
                   provenance.c_str());
    }
  } else {
    return Fail(absl::InvalidArgumentError("--what must be samples, curve, param-samples or param-curve"));
  }
  if (!status.ok()) return Fail(status);
  return 0;
}

int RunSurfaces() {
  PrintCatalog("surfaces (--surface NAME[:KEY=VALUE;...]):", SurfaceCatalog());
  PrintCatalog("\ndensities (--density NAME[:KEY=VALUE;...] or expr:EXPRESSION):", DensityCatalog());
  std::printf("\ncurves (--curve): hilbert (2x2), hilbert2 (3x3 meander), peano (3x3 serpentine)\n");
  std::printf("sequences (--sequence): jittered (default), equal, random, vandercorput, progressive\n");
  std::printf("estimators (--estimator): triangle (a), square (b), fff (c, default), quadrature\n");
  return 0;
}

}  // namespace
}  // namespace sfc

int main(int argc, char** argv) {
  CLI::App app{"sfcsampler: density-controlled low-discrepancy samples on parametric surfaces"};
  app.require_subcommand(1);

  sfc::RequestFlags flags;
  sfc::Connection conn;
  auto add_connection = [&conn](CLI::App* cmd) {
    cmd->add_option("--server", conn.server, "HOST:PORT of an sfcsampler-server (default: run in-process)");
    cmd->add_option("--token-file", conn.token_file, "file with the server's bearer token");
    cmd->add_flag("--tls", conn.tls, "connect with TLS (system roots)");
    cmd->add_option("--tls-roots", conn.tls_roots, "PEM roots to trust for TLS (implies --tls)");
    cmd->add_option("--tls-cert", conn.tls_cert,
                    "PEM client certificate for servers that require mutual TLS (implies --tls)");
    cmd->add_option("--tls-key", conn.tls_key, "PEM private key of --tls-cert");
  };
  sfc::OutputFlags out;
  sfc::Verbosity verbosity;

  CLI::App* sample = app.add_subcommand("sample", "sample a surface (in-process, or over the wire with --server)");
  sfc::AddTreeFlags(sample, &flags);
  sfc::AddSampleFlags(sample, &flags);
  sample->add_option("--format", out.format, "csv | ply | npy (numpy.load gives a structured array)")
      ->capture_default_str();
  sample->add_flag("--ascii", out.ascii, "write ASCII PLY instead of binary little-endian");
  sample->add_option("--output,-o", out.output, "output file, - for stdout")->capture_default_str();
  sample->add_option("--batch-size", out.batch_size,
                     "samples per batch; 0 = 65536 in-process, or as many as fit the server's "
                     "max_message_bytes (a larger value is refused with the largest that fits)")
      ->capture_default_str()
      ->check(CLI::Range(0, 1 << 24));
  sample->add_option("--precision", out.precision,
                     "float64 | float32: width of the float columns (float32 halves the file and the "
                     "wire; values are the float64 ones rounded)")
      ->capture_default_str();
  sample->add_flag("--quiet,-q", verbosity.quiet,
                   "no summary and no progress on stderr (depth-cap warnings still show)");
  sample->add_flag("--no-warnings", verbosity.no_warnings, "do not print the depth-cap warnings");
  add_connection(sample);

  sfc::SampleManyFlags many_flags;
  CLI::App* sample_many = sfc::AddSampleManyCommand(&app, &many_flags);

  CLI::App* prepare = app.add_subcommand("prepare", "build (warm) a curve tree and print its key and statistics");
  sfc::AddTreeFlags(prepare, &flags);
  prepare->add_option("--count,-n", flags.count, "size the tree for this many samples")->capture_default_str();
  add_connection(prepare);
  CLI::App* cache = app.add_subcommand("cache", "print the server's tree-cache statistics and limits");
  add_connection(cache);
  CLI::App* health = app.add_subcommand("health", "check the server's grpc.health.v1 status");
  add_connection(health);
  std::vector<std::string> upload_specs;
  CLI::App* upload = app.add_subcommand(
      "upload", "send model files to the server once (only if it lacks them) and print FORMAT:sha256=HASH "
                "specs that any job can name; sample and prepare with --server do this by themselves");
  upload->add_option("models", upload_specs, "FORMAT:FILE, FORMAT one of step iges nurbs obj ply")->required();
  add_connection(upload);

  app.add_subcommand("surfaces", "list the surfaces, densities, curves and sequences with their formulas");
  std::vector<std::string> inspect_specs;
  CLI::App* inspect = app.add_subcommand(
      "inspect", "list a CAD model's faces (index as in the face column, type, trimmed area, "
                 "parameter box, orientation, trim) and the order the curve visits them");
  inspect->add_option("models", inspect_specs, "step:FILE, iges:FILE or nurbs:FILE")->required();

  sfc::EvalFlags eval_flags;
  CLI::App* eval = app.add_subcommand("eval", "run the paper's discrepancy protocol and compare slopes with Tables 1-2");
  eval->add_option("--setting", eval_flags.setting, "fast (N up to 12288, seconds) or full (the paper's 2 to 1572864, minutes)")
      ->capture_default_str();
  eval->add_option("--l-min", eval_flags.l_min, "smallest l (N = 2^l and 2^l + 2^(l-1))");
  eval->add_option("--l-max", eval_flags.l_max, "largest l");
  eval->add_option("--plane-methods", eval_flags.plane, "subset of: random jittered2d sobol halton hammersley hilbert-jittered hilbert2-jittered peano-jittered")
      ->delimiter(',');
  eval->add_option("--sphere-methods", eval_flags.sphere, "subset of: random hammersley fibonacci hilbert-jittered-fff hilbert-jittered-triangle hilbert-jittered-quadrature")
      ->delimiter(',');
  eval->add_option("--out-dir", eval_flags.out_dir, "where the CSV, the slope tables and the plots go")->capture_default_str();
  eval->add_option("--seed", eval_flags.seed, "seed of the random and jittered sets")->capture_default_str();
  eval->add_option("--model", eval_flags.model,
                   "model mode: a sphere-shaped model (step:sphere.step, ply:icosphere.ply, ...) "
                   "against the built-in sphere, spherical-triangle discrepancy, N = 64..24576");
  eval->add_option("--seeds", eval_flags.seeds, "model mode: seeds averaged per N")->capture_default_str();
  sfc::AddEvalQualityFlags(eval, &eval_flags.quality);
  add_connection(eval);

  sfc::RenderFlags render_flags;
  CLI::App* render = app.add_subcommand("render", "draw samples or the adaptive curve as a PNG");
  sfc::AddTreeFlags(render, &flags);
  sfc::AddSampleFlags(render, &flags);
  render->add_option("--what", render_flags.what, "samples | curve | param-samples | param-curve")->capture_default_str();
  render->add_option("--view", render_flags.view, "AZIMUTH,ELEVATION in degrees")->capture_default_str();
  render->add_option("--size", render_flags.size, "picture width and height in pixels")->capture_default_str();
  render->add_option("--title", render_flags.title, "caption");
  render->add_option("--output,-o", render_flags.output, "PNG file")->capture_default_str();
  add_connection(render);

  CLI11_PARSE(app, argc, argv);
  if (sample->parsed()) return sfc::RunSample(flags, out, verbosity, conn);
  if (sample_many->parsed()) return sfc::RunSampleMany(many_flags);
  if (prepare->parsed()) return sfc::RunPrepare(flags, conn);
  if (cache->parsed()) return sfc::RunCache(conn);
  if (health->parsed()) return sfc::RunHealth(conn);
  if (upload->parsed()) return sfc::RunUpload(upload_specs, conn);
  if (inspect->parsed()) return sfc::RunInspect(inspect_specs);
  if (eval->parsed()) return sfc::RunEval(eval_flags, conn);
  if (render->parsed()) return sfc::RunRender(flags, render_flags, conn);
  return sfc::RunSurfaces();
}
