// `sfcsampler sample`: one surface's samples (a whole set, a range, a shard
// or a region) written as CSV, PLY or NPY to a file or stdout, in process or
// from --server; the tree summary, progress and warnings go to stderr.
#include <chrono>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "base/status_macros.h"
#include "client/cli/commands.h"
#include "client/cli/connection_flags.h"
#include "client/cli/exit_status.h"
#include "client/cli/model_read_flags.h"
#include "client/cli/sample_source.h"
#include "client/sample_writer.h"
#include "request/request_flags.h"
#include "request/stream_options.h"

namespace sfc {
namespace {

struct SampleFlags {
  RequestFlags request;
  std::string format = "csv";
  bool ascii = false;
  std::string output = "-";
  size_t batch_size = 0;  // 0: SampleSourceOptions::batch_size's default
  std::string precision = "float64";
  std::vector<std::string> columns;  // --columns (empty: every column)
  Verbosity verbosity;
  ConnectionFlags connection;
  ModelReadFlags model_read;
};

absl::StatusOr<OutputFormat> ParseFormat(const std::string& format, bool ascii) {
  if (format == "csv") return OutputFormat::kCsv;
  if (format == "ply") return ascii ? OutputFormat::kPlyAscii : OutputFormat::kPlyBinary;
  if (format == "npy") return OutputFormat::kNpy;
  return absl::InvalidArgumentError("--format must be csv, ply or npy");
}

int RunSample(const SampleFlags& flags) {
  auto request = ToSampleRequest(flags.request);
  if (!request.ok()) return Fail(request.status());
  auto format = ParseFormat(flags.format, flags.ascii);
  if (!format.ok()) return Fail(format.status());
  auto precision = ParseColumnPrecision(flags.precision);
  if (!precision.ok()) return Fail(precision.status());
  if (auto s = SampleWriter::CheckColumns(*format, request->fields, flags.columns); !s.ok()) {
    return Fail(s);
  }
  // Columns the file leaves out are neither made nor sent.
  request->fields = SampleWriter::SourceFields(request->fields, flags.columns);
  const auto start = std::chrono::steady_clock::now();
  // Float32 output asks a server for float32 columns: half the bytes, and
  // the same file (the writer rounds doubles to floats the same way).
  SampleSourceOptions options;
  options.batch_size = flags.batch_size;
  options.precision = *precision;
  if (absl::Status read = ApplyModelReadFlags(flags.model_read, &options); !read.ok()) {
    return Fail(read);
  }
  auto source = OpenSampleSource(flags.connection, options);
  if (!source.ok()) return Fail(source.status());
  std::unique_ptr<SampleWriter> writer;
  Progress progress(!flags.verbosity.quiet);
  auto provenance = (*source)->Sample(
      *request, &progress, [&](const TreeReport& tree) { PrintTreeSummary(tree, flags.verbosity); },
      [&](std::optional<uint64_t> expected, const SampleBatch& batch) {
        if (!writer) {
          ASSIGN_OR_RETURN(writer, SampleWriter::Open(flags.output, *format, request->fields,
                                                      expected, *precision, flags.columns));
        }
        return writer->Write(batch);
      });
  if (!provenance.ok()) return Fail(provenance.status());
  if (!writer) {  // a region with no samples: still write a valid, empty file
    auto opened =
        SampleWriter::Open(flags.output, *format, request->fields, std::nullopt, *precision,
                           flags.columns);
    if (!opened.ok()) return Fail(opened.status());
    writer = *std::move(opened);
  }
  if (auto s = writer->Finish(); !s.ok()) return Fail(s);
  if (!flags.verbosity.quiet) {
    std::fprintf(stderr, "%llu samples written to %s in %.3f s %s\n",
                 static_cast<unsigned long long>(writer->written()), flags.output.c_str(),
                 std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(),
                 provenance->c_str());
  }
  return 0;
}

}  // namespace

Command AddSampleCommand(CLI::App& app) {
  auto flags = std::make_shared<SampleFlags>();
  CLI::App* sample =
      app.add_subcommand("sample", "sample a surface (in-process, or over the wire with --server)");
  AddTreeFlags(sample, &flags->request);
  AddSampleFlags(sample, &flags->request);
  sample
      ->add_option("--format", flags->format,
                   "csv | ply | npy (numpy.load gives a structured array)")
      ->capture_default_str();
  sample->add_flag("--ascii", flags->ascii, "write ASCII PLY instead of binary little-endian");
  sample->add_option("--output,-o", flags->output, "output file, - for stdout")
      ->capture_default_str();
  sample
      ->add_option("--batch-size", flags->batch_size,
                   absl::StrCat("samples per batch; 0 = ", kDefaultBatchSize,
                                " in-process, or as many as fit the server's max_message_bytes "
                                "(a larger value is refused with the largest that fits)"))
      ->capture_default_str()
      ->check(CLI::Range(0, 1 << 24));
  sample
      ->add_option("--precision", flags->precision,
                   "float64 | float32: width of the float columns (float32 halves the file and the "
                   "wire; values are the float64 ones rounded)")
      ->capture_default_str();
  sample
      ->add_option("--columns", flags->columns,
                   "write only these columns, comma-separated (e.g. x,y,z; default all): index, "
                   "u, v, x, y, z, nx, ny, nz, density, curve_position, face, triangle")
      ->delimiter(',');
  sample->add_flag("--quiet,-q", flags->verbosity.quiet,
                   "no summary and no progress on stderr (depth-cap warnings still show)");
  sample->add_flag("--no-warnings", flags->verbosity.no_warnings,
                   "do not print the depth-cap warnings");
  AddConnectionFlags(sample, &flags->connection);
  AddModelReadFlags(sample, &flags->model_read);
  return {sample, [flags] { return RunSample(*flags); }};
}

}  // namespace sfc
