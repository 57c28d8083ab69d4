#include "client/cli/eval_protocol.h"

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include "absl/strings/str_format.h"
#include "base/status_macros.h"
#include "client/cli/exit_status.h"
#include "evaluation/plot.h"

namespace sfc {
namespace {

// Writes the protocol's CSV, slope tables and plots into `out_dir`.
absl::Status WriteProtocolOutputs(const std::vector<ProtocolRow>& rows, const std::string& tables,
                                  const std::string& out_dir) {
  std::error_code mkdir_error;
  std::filesystem::create_directories(out_dir, mkdir_error);
  if (mkdir_error) {
    return absl::UnavailableError(
        absl::StrFormat("cannot create the folder \"%s\": %s", out_dir, mkdir_error.message()));
  }
  auto write = [&](const std::string& name, const std::string& text) {
    std::FILE* out = std::fopen((out_dir + "/" + name).c_str(), "w");
    if (!out) return false;
    std::fputs(text.c_str(), out);
    return std::fclose(out) == 0;
  };
  if (!write("discrepancy.csv", RowsCsv(rows)) || !write("slopes.md", tables)) {
    return absl::UnavailableError("cannot write into " + out_dir);
  }
  for (const char* measure : {"rectangular", "circular", "triangular"}) {
    RETURN_IF_ERROR(PlotDiscrepancy(rows, "plane", measure, out_dir + "/plane-" + measure));
  }
  RETURN_IF_ERROR(PlotDiscrepancy(rows, "sphere", "spherical", out_dir + "/sphere-spherical"));
  std::set<std::string> surfaces;
  for (const ProtocolRow& row : rows) {
    if (row.density) surfaces.insert(row.domain);
  }
  for (const std::string& domain : surfaces) {
    std::string stem = domain.substr(8);  // after "surface "
    for (char& c : stem) {
      if (!std::isalnum(static_cast<unsigned char>(c))) c = '-';
    }
    RETURN_IF_ERROR(PlotDiscrepancy(rows, domain, "density", out_dir + "/surface-" + stem));
  }
  return absl::OkStatus();
}

}  // namespace

int RunEvalProtocol(ProtocolOptions options, const std::string& out_dir, SampleSource* server) {
  if (server != nullptr) {
    options.our_sets = [server](const std::string& surface, const std::string& density,
                                const CurveTreeOptions& tree_options, uint64_t count,
                                uint64_t seed) -> absl::StatusOr<SampleBatch> {
      SampleRequest request;
      request.tree.surface = surface;
      request.tree.density = density;
      request.tree.options = tree_options;
      request.sequence = SequenceKind::kJittered;
      request.count = count;
      request.seed = seed;
      return CollectSamples(*server, request);
    };
  }
  const auto start = std::chrono::steady_clock::now();
  const bool tty = isatty(STDERR_FILENO);
  auto rows = RunProtocol(options, [&](int done, int total) {
    // On a terminal a live counter; in a log a line every tenth.
    if (!tty && done % std::max(1, total / 10) != 0 && done != total) return;
    std::fprintf(stderr,
                 tty ? "\reval: %d / %d point sets, %.0f s" : "eval: %d / %d point sets, %.0f s\n",
                 done, total,
                 std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  });
  std::fprintf(stderr, "\n");
  if (!rows.ok()) return Fail(rows.status());
  const std::string tables = SlopeTables(Slopes(*rows));
  std::printf("N = 2^l and 2^l + 2^(l-1), l = %d..%d, seed %llu\n\n%s", options.l_min,
              options.l_max, static_cast<unsigned long long>(options.seed), tables.c_str());
  if (auto written = WriteProtocolOutputs(*rows, tables, out_dir); !written.ok())
    return Fail(written);
  std::fprintf(stderr, "wrote %s/discrepancy.csv, slopes.md and plots (svg, png)\n",
               out_dir.c_str());
  return 0;
}

}  // namespace sfc
