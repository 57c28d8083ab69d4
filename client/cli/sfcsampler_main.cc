// sfcsampler: the command-line interface. Without --server every subcommand
// runs the sampler in-process (the embedded default).
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <iostream>

#include "CLI/CLI.hpp"
#include "absl/strings/str_format.h"
#include "catalog/catalog.h"
#include "client/cli/request_flags.h"
#include "client/sample_writer.h"
#include "client/sampler_client.h"
#include "core/area_estimator.h"
#include "core/curve.h"
#include "core/sequence.h"
#include "engine/sampling_engine.h"
#include "proto/convert.h"

namespace sfc {
namespace {

int Fail(const absl::Status& status) {
  std::fprintf(stderr, "sfcsampler: %s: %s\n", absl::StatusCodeToString(status.code()).c_str(),
               std::string(status.message()).c_str());
  return status.code() == absl::StatusCode::kInvalidArgument ? 2 : 1;
}

void PrintPrecision(const PrecisionReport& report) {
  if (report.geometry_capped_leaves == 0 && report.mass_capped_leaves == 0) return;
  std::fprintf(stderr,
               "warning: the depth cap stopped splits the tests still wanted (paper Sect. 5.3): "
               "%llu leaves for flatness, %llu for mass\n",
               static_cast<unsigned long long>(report.geometry_capped_leaves),
               static_cast<unsigned long long>(report.mass_capped_leaves));
  for (const DepthCapHit& h : report.worst) {
    std::fprintf(stderr, "  %s test at cell u in [%.9g, %.9g], v in [%.9g, %.9g]: %.6g vs limit %.6g (x%.3g)\n",
                 h.test == DepthCapHit::Test::kGeometry ? "flatness" : "mass", h.u0, h.u0 + h.size,
                 h.v0, h.v0 + h.size, h.measured, h.limit, h.measured / h.limit);
  }
}

void PrintTree(const PreparedTree& t, double seconds) {
  const CurveTree& tree = *t.lookup.tree;
  std::fprintf(stderr,
               "tree %s: %zu leaves, depth %d..%d, %zu bytes (%zu per leaf), tolerance %.6g, built "
               "in %.3f s\n",
               t.key.HexWithGrade(t.grade).c_str(), tree.leaf_count(), tree.min_depth(),
               tree.max_depth(), tree.leaf_count() * CurveTree::kBytesPerLeaf,
               CurveTree::kBytesPerLeaf, tree.options().tolerance, seconds);
  PrintPrecision(tree.precision());
}

// Where to run: in-process (server empty) or over the wire.
struct Connection {
  std::string server;      // host:port; "" = embedded
  std::string token_file;  // bearer token
  bool tls = false;
  std::string tls_roots;
};

absl::StatusOr<std::unique_ptr<SamplerClient>> Connect(const Connection& c, uint32_t batch_size) {
  ClientOptions options;
  options.target = c.server;
  options.tls = c.tls || !c.tls_roots.empty();
  options.tls_root_certs_file = c.tls_roots;
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

void PrintTreeInfo(const ::sfcsampler::v1::TreeInfo& t) {
  std::fprintf(stderr, "tree %s (%s): %llu leaves, depth %d..%d, %llu bytes, tolerance %.6g\n",
               t.key_with_grade().c_str(),
               t.cache_hit() ? "cache hit" : t.refined() ? "refined from cache" : "built",
               static_cast<unsigned long long>(t.leaves()), t.min_depth(), t.max_depth(),
               static_cast<unsigned long long>(t.bytes()), t.tolerance());
  if (t.flatness_capped_leaves() || t.mass_capped_leaves()) {
    std::fprintf(stderr,
                 "warning: the depth cap stopped splits the tests still wanted (paper Sect. 5.3): "
                 "%llu leaves for flatness, %llu for mass\n",
                 static_cast<unsigned long long>(t.flatness_capped_leaves()),
                 static_cast<unsigned long long>(t.mass_capped_leaves()));
    for (const auto& w : t.warnings()) {
      std::fprintf(stderr, "  %s test at cell u in [%.9g, %.9g], v in [%.9g, %.9g]: %.6g vs limit %.6g\n",
                   w.test().c_str(), w.u0(), w.u0() + w.size(), w.v0(), w.v0() + w.size(),
                   w.measured(), w.limit());
    }
  }
}

int RunSample(const RequestFlags& flags, const std::string& format, bool ascii,
              const std::string& output, size_t batch_size, bool quiet, const Connection& conn) {
  auto request = ToSampleRequest(flags);
  if (!request.ok()) return Fail(request.status());
  OutputFormat out_format;
  if (format == "csv") {
    out_format = OutputFormat::kCsv;
  } else if (format == "ply") {
    out_format = ascii ? OutputFormat::kPlyAscii : OutputFormat::kPlyBinary;
  } else {
    return Fail(absl::InvalidArgumentError("--format must be csv or ply"));
  }
  const auto start = std::chrono::steady_clock::now();
  if (!conn.server.empty()) {
    auto client = Connect(conn, static_cast<uint32_t>(batch_size));
    if (!client.ok()) return Fail(client.status());
    std::unique_ptr<SampleWriter> writer;
    const bool progress = !quiet && isatty(STDERR_FILENO);
    auto summary = (*client)->Sample(
        *request, [&](const ::sfcsampler::v1::StreamHeader& header, const SampleBatch& batch) {
          if (!writer) {
            if (!quiet) PrintTreeInfo(header.tree());
            std::optional<uint64_t> expected;
            if (header.expected_samples() >= 0) expected = header.expected_samples();
            auto opened = SampleWriter::Open(output, out_format, request->fields, expected);
            if (!opened.ok()) return opened.status();
            writer = *std::move(opened);
          }
          if (progress && header.end() - header.begin() >= 1'000'000) {
            std::fprintf(stderr, "\r%llu / %llu samples",
                         static_cast<unsigned long long>(writer->written() + batch.size()),
                         static_cast<unsigned long long>(header.end() - header.begin()));
          }
          return writer->Write(batch);
        });
    if (progress) std::fprintf(stderr, "\n");
    if (!summary.ok()) return Fail(summary.status());
    if (!writer) {  // a region with no samples: still write a valid, empty file
      auto opened = SampleWriter::Open(output, out_format, request->fields, std::nullopt);
      if (!opened.ok()) return Fail(opened.status());
      writer = *std::move(opened);
    }
    if (auto s = writer->Finish(); !s.ok()) return Fail(s);
    if (!quiet) {
      std::fprintf(stderr, "%llu samples written to %s in %.3f s from %s (%s, seed %llu, %d resumes)\n",
                   static_cast<unsigned long long>(writer->written()), output.c_str(),
                   std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(),
                   conn.server.c_str(), summary->header.algorithm_version().c_str(),
                   static_cast<unsigned long long>(request->seed), summary->resumes);
    }
    return 0;
  }
  DirectTreeSource source;
  SamplingEngine engine(EngineLimits{}, &source);
  auto job = engine.Start(*request);
  if (!job.ok()) return Fail(job.status());
  const double build_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!quiet) PrintTree(job->tree, build_seconds);

  std::optional<uint64_t> expected;
  if (request->region.kind == Region::Kind::kAll) expected = job->end - job->begin;
  auto writer = SampleWriter::Open(output, out_format, request->fields, expected);
  if (!writer.ok()) return Fail(writer.status());
  SampleBatch batch;
  const bool progress = !quiet && isatty(STDERR_FILENO) && job->end - job->begin >= 1'000'000;
  uint64_t done = 0;
  while (true) {
    batch.Clear();
    auto n = job->cursor->Next(batch_size, &batch);
    if (!n.ok()) return Fail(n.status());
    if (*n == 0) break;
    if (auto s = (*writer)->Write(batch); !s.ok()) return Fail(s);
    done += *n;
    if (progress) {
      std::fprintf(stderr, "\r%llu / %llu samples", static_cast<unsigned long long>(done),
                   static_cast<unsigned long long>(job->end - job->begin));
    }
  }
  if (progress) std::fprintf(stderr, "\n");
  if (auto s = (*writer)->Finish(); !s.ok()) return Fail(s);
  if (!quiet) {
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::fprintf(stderr, "%llu samples written to %s in %.3f s (%s, seed %llu)\n",
                 static_cast<unsigned long long>((*writer)->written()), output.c_str(), seconds,
                 kAlgorithmVersion, static_cast<unsigned long long>(request->seed));
  }
  return 0;
}

int RunPrepare(const RequestFlags& flags, const Connection& conn) {
  auto spec = ToTreeSpec(flags);
  if (!spec.ok()) return Fail(spec.status());
  if (!conn.server.empty()) {
    auto client = Connect(conn, 0);
    if (!client.ok()) return Fail(client.status());
    auto response = (*client)->Prepare(*spec, flags.tree_count ? flags.tree_count : flags.count);
    if (!response.ok()) return Fail(response.status());
    PrintTreeInfo(response->tree());
    std::fprintf(stderr, "prepared in %.3f s\n", response->seconds());
    std::printf("%s\n", response->tree().key_with_grade().c_str());
    return 0;
  }
  DirectTreeSource source;
  SamplingEngine engine(EngineLimits{}, &source);
  const auto start = std::chrono::steady_clock::now();
  auto prepared = engine.Prepare(*spec, flags.tree_count ? flags.tree_count : flags.count);
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
  };
  std::string format = "csv", output = "-";
  bool ascii = false, quiet = false;
  size_t batch_size = 65536;

  CLI::App* sample = app.add_subcommand("sample", "sample a surface (in-process)");
  sfc::AddTreeFlags(sample, &flags);
  sfc::AddSampleFlags(sample, &flags);
  sample->add_option("--format", format, "csv | ply")->capture_default_str();
  sample->add_flag("--ascii", ascii, "write ASCII PLY instead of binary little-endian");
  sample->add_option("--output,-o", output, "output file, - for stdout")->capture_default_str();
  sample->add_option("--batch-size", batch_size, "samples per batch")->capture_default_str()->check(CLI::Range(1, 1 << 24));
  sample->add_flag("--quiet,-q", quiet, "no summary on stderr");
  add_connection(sample);

  CLI::App* prepare = app.add_subcommand("prepare", "build (warm) a curve tree and print its key and statistics");
  sfc::AddTreeFlags(prepare, &flags);
  prepare->add_option("--count,-n", flags.count, "size the tree for this many samples")->capture_default_str();
  add_connection(prepare);
  CLI::App* cache = app.add_subcommand("cache", "print the server's tree-cache statistics and limits");
  add_connection(cache);
  CLI::App* health = app.add_subcommand("health", "check the server's grpc.health.v1 status");
  add_connection(health);

  app.add_subcommand("surfaces", "list the surfaces, densities, curves and sequences with their formulas");

  CLI11_PARSE(app, argc, argv);
  if (sample->parsed()) return sfc::RunSample(flags, format, ascii, output, batch_size, quiet, conn);
  if (prepare->parsed()) return sfc::RunPrepare(flags, conn);
  if (cache->parsed()) return sfc::RunCache(conn);
  if (health->parsed()) return sfc::RunHealth(conn);
  return sfc::RunSurfaces();
}
