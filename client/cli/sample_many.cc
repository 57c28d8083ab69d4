#include "client/cli/sample_many.h"

#include <glob.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <optional>
#include <thread>

#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/str_format.h"
#include "absl/strings/strip.h"
#include "base/status_macros.h"
#include "client/cli/commands.h"
#include "client/cli/connection_flags.h"
#include "client/cli/progress.h"
#include "client/cli/sample_source.h"
#include "client/sample_writer.h"
#include "engine/model_source.h"
#include "request/model_files.h"
#include "request/stream_options.h"

namespace sfc {
namespace {

namespace fs = std::filesystem;

// The model format of a file name's extension (request/model_files.h), e.g. "step".
std::optional<std::string> FormatOf(const std::string& path) {
  const std::optional<ModelFormat> format = ModelFormatOfPath(path);
  if (!format) return std::nullopt;
  return std::string(ModelFormatName(*format));
}

// One model file and its name: its path relative to the input that named it
// (a folder, a pattern's folder, a list file's folder), which is also where
// its output goes under --output-dir.
struct Named {
  std::string path, name;
};

// The name of `path` relative to `root` ("" = the path's file name).
std::string RelativeName(const std::string& path, const std::string& root) {
  if (root.empty()) return fs::path(path).filename().string();
  return fs::path(path).lexically_relative(root).lexically_normal().string();
}

// A list entry's name: the path as written, normalised, without a leading
// "/" or "../" (so that outputs stay under --output-dir).
std::string ListName(const std::string& entry) {
  std::string name = fs::path(entry).lexically_normal().string();
  while (true) {
    if (absl::StartsWith(name, "/")) {
      name.erase(0, 1);
    } else if (absl::StartsWith(name, "../")) {
      name.erase(0, 3);
    } else {
      return name;
    }
  }
}

// The model files one input names: a folder's (recursively, by extension), a
// pattern's matches, a list file's lines (in its order) or one model file.
// Folders and patterns are sorted by name.
absl::StatusOr<std::vector<Named>> Expand(const std::string& input) {
  std::vector<Named> out;
  std::error_code error;
  auto sorted = [&out] {
    std::sort(out.begin(), out.end(),
              [](const Named& a, const Named& b) { return a.name < b.name; });
  };
  if (fs::is_directory(input, error)) {
    for (auto it = fs::recursive_directory_iterator(input, error); !error && it != fs::end(it);
         it.increment(error)) {
      const std::string path = it->path().string();
      if (it->is_regular_file(error) && FormatOf(path))
        out.push_back({path, RelativeName(path, input)});
    }
    if (error)
      return absl::InvalidArgumentError(
          absl::StrFormat("cannot list %s: %s", input, error.message()));
    sorted();
    if (out.empty()) {
      return absl::InvalidArgumentError(
          absl::StrFormat("the folder %s has no model files (%s)", input, ModelExtensionList()));
    }
    return out;
  }
  if (input.find_first_of("*?[") != std::string::npos) {
    // Names are relative to the folder before the first wildcard.
    const size_t wild = input.find_first_of("*?[");
    const size_t slash = input.rfind('/', wild);
    const std::string root = slash == std::string::npos ? "." : input.substr(0, slash + 1);
    glob_t matches;
    const int rc = glob(input.c_str(), 0, nullptr, &matches);
    for (size_t i = 0; rc == 0 && i < matches.gl_pathc; ++i) {
      const std::string path = matches.gl_pathv[i];
      if (fs::is_regular_file(path, error)) out.push_back({path, RelativeName(path, root)});
    }
    globfree(&matches);
    sorted();
    if (out.empty())
      return absl::InvalidArgumentError(absl::StrFormat("the pattern %s matches no files", input));
    return out;
  }
  if (FormatOf(input)) return std::vector<Named>{{input, RelativeName(input, "")}};
  std::ifstream list(input);
  if (!list) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "%s is not a folder, a pattern, a list file or a model file", input));
  }
  const fs::path base = fs::path(input).parent_path();
  std::string line;
  while (std::getline(list, line)) {
    const std::string entry(absl::StripAsciiWhitespace(line));
    if (entry.empty() || entry[0] == '#') continue;
    out.push_back({(base / entry).string(), ListName(entry)});
  }
  return out;
}

// NAME without its model extension, plus ".FORMAT"; with the extension kept
// when `keep_extension` (two models of one stem, e.g. part.step and part.iges).
std::string OutputName(const std::string& name, const std::string& format, bool keep_extension) {
  const fs::path p(name);
  if (keep_extension || !FormatOf(name)) return name + "." + format;
  return (p.parent_path() / p.stem()).string() + "." + format;
}

absl::StatusOr<std::string> ReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return absl::NotFoundError(absl::StrFormat("cannot open %s", path));
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) return absl::DataLossError(absl::StrFormat("cannot read %s", path));
  return bytes;
}

struct Outcome {
  std::string path, name, sha256, output, error;
  uint64_t seed = 0, samples = 0;
  double seconds = 0;
  bool done = false;
};

struct Job {
  const SampleManyFlags* flags;
  OutputFormat format;
  OutputPrecision precision;
  SampleSource* source;  // in process, or the server
};

// Samples one model into its output file (written under a temporary name,
// renamed when complete). Fills `o` and returns the model's error, if any.
absl::Status SampleOne(const Job& job, Outcome* o) {
  ASSIGN_OR_RETURN(const std::string bytes, ReadFile(o->path));
  o->sha256 = Sha256Hex(bytes);
  o->seed = ModelSeed(job.flags->request.seed, o->sha256);
  RequestFlags flags = job.flags->request;
  const std::string format = *FormatOf(o->path);
  flags.surface = format + ":" + o->path;
  flags.seed = o->seed;
  // The model columns apply to the models that have them: --face to CAD
  // models, --triangle to meshes.
  const bool mesh = format == "obj" || format == "ply";
  flags.face = flags.face && !mesh;
  flags.triangle = flags.triangle && mesh;
  ASSIGN_OR_RETURN(SampleRequest request, ToSampleRequest(flags));
  // --columns likewise: the other kind's column is dropped for this model.
  std::vector<std::string> columns;
  for (const std::string& c : job.flags->columns) {
    if (c != (mesh ? "face" : "triangle")) columns.push_back(c);
  }
  if (!job.flags->columns.empty() && columns.empty()) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "--columns: this model has no %s column (it is for %s); name a column it has",
        mesh ? "face" : "triangle", mesh ? "CAD models" : "meshes"));
  }
  request.fields = SampleWriter::SourceFields(request.fields, columns);  // neither made nor sent
  std::error_code error;
  fs::create_directories(fs::path(o->output).parent_path(), error);
  const std::string part = o->output + ".part";
  std::unique_ptr<SampleWriter> writer;
  Progress silent(false);
  absl::Status status =
      job.source
          ->Sample(request, &silent, /*on_tree=*/nullptr,
                   [&](std::optional<uint64_t> expected, const SampleBatch& batch) {
                     if (!writer) {
                       ASSIGN_OR_RETURN(writer, SampleWriter::Open(part, job.format, request.fields,
                                                                   expected, job.precision,
                                                                   columns));
                     }
                     return writer->Write(batch);
                   })
          .status();
  if (status.ok() && !writer) {  // a region with no samples: still a valid, empty file
    auto opened =
        SampleWriter::Open(part, job.format, request.fields, std::nullopt, job.precision, columns);
    if (opened.ok()) writer = *std::move(opened);
    status = opened.status();
  }
  if (status.ok()) status = writer->Finish();
  if (!writer) {
    fs::remove(part, error);
    return status;
  }
  o->samples = writer->written();
  writer.reset();
  if (status.ok()) {
    fs::rename(part, o->output, error);
    if (error)
      status = absl::InternalError(absl::StrFormat("cannot rename %s: %s", part, error.message()));
  }
  if (!status.ok()) fs::remove(part, error);
  return status;
}

// "[#####.....] k/N models, f failed, S samples" on a terminal.
class Bar {
 public:
  Bar(size_t total, bool enabled) : total_(total), enabled_(enabled && isatty(STDERR_FILENO)) {}
  void Step(bool failed, uint64_t samples) {
    std::lock_guard<std::mutex> lock(mu_);
    ++done_;
    failed_ += failed;
    samples_ += samples;
    if (!enabled_) return;
    const size_t width = 30, filled = width * done_ / std::max<size_t>(total_, 1);
    std::fprintf(stderr, "\r[%s%s] %zu/%zu models, %zu failed, %llu samples ",
                 std::string(filled, '#').c_str(), std::string(width - filled, '.').c_str(), done_,
                 total_, failed_, static_cast<unsigned long long>(samples_));
    std::fflush(stderr);
  }
  void Clear() {
    if (enabled_) std::fprintf(stderr, "\r\033[K");
  }

 private:
  const size_t total_;
  const bool enabled_;
  std::mutex mu_;
  size_t done_ = 0, failed_ = 0;
  uint64_t samples_ = 0;
};

int Usage(const std::string& message) {
  std::fprintf(stderr, "sfcsampler sample-many: %s\n", message.c_str());
  return 2;
}

}  // namespace

Command AddSampleManyCommand(CLI::App& app) {
  auto flags = std::make_shared<SampleManyFlags>();
  SampleManyFlags* f = flags.get();
  CLI::App* cmd = app.add_subcommand(
      "sample-many",
      "sample many model files (a folder, a glob, a list file) in parallel, one output per model; "
      "each model's seed comes from --seed and its content hash");
  cmd->add_option(
         "inputs", f->inputs,
         "folders (their " + ModelExtensionList() +
             " files, in subfolders too), glob patterns, list files (a path a line) or model "
             "files")
      ->required();
  cmd->add_option("--output-dir,-O", f->out_dir,
                  "where the outputs go: one NAME.FORMAT per model, NAME its path relative to the "
                  "folder (or pattern, or list file) that named it")
      ->capture_default_str();
  cmd->add_option("--format", f->format, "npy | csv | ply")->capture_default_str();
  cmd->add_flag("--ascii", f->ascii, "ASCII PLY instead of binary little-endian");
  cmd->add_option("--precision", f->precision, "float64 | float32")->capture_default_str();
  cmd->add_option("--columns", f->columns,
                  "write only these columns, comma-separated (e.g. x,y,z; default all): index, u, "
                  "v, x, y, z, nx, ny, nz, density, curve_position, face, triangle")
      ->delimiter(',');
  cmd->add_option("--jobs,-j", f->jobs,
                  "models sampled at once (0 = the hardware threads, at most 8)")
      ->capture_default_str()
      ->check(CLI::Range(0, 256));
  cmd->add_option(
      "--manifest", f->manifest,
      "also write a TSV: name, sha256, seed, samples, output, error (one row per model)");
  cmd->add_flag("--quiet,-q", f->quiet, "no progress bar and no summary (failures still print)");
  AddModelReadFlags(cmd, &f->model_read);
  // With --server each model is uploaded once, only if the server lacks its bytes.
  AddConnectionFlags(cmd, &f->connection);
  // The tree and set flags of `sample`, the same for every model (not --surface).
  RequestFlags* r = &f->request;
  cmd->add_option("--density", r->density,
                  "density spec (uniform, gaussian:floor=F, mean:floor=F, expr:...)")
      ->capture_default_str();
  cmd->add_option("--curve", r->curve, "hilbert | hilbert2 | peano (CAD models)")
      ->capture_default_str();
  cmd->add_option("--estimator", r->estimator, "triangle | square | fff | quadrature (CAD models)")
      ->capture_default_str();
  cmd->add_option("--tolerance", r->tolerance, "the paper's a (0 = the default)")
      ->capture_default_str();
  cmd->add_option("--depth-cap", r->depth_cap, "the paper's r (0 = deepest)")
      ->capture_default_str();
  cmd->add_option("--rho", r->rho, "max samples' worth of mass per leaf")->capture_default_str();
  AddSampleFlags(cmd, r);
  cmd->get_option("--seed")->description(
      "base seed: each model's seed is derived from it and the model's SHA-256 (--manifest lists "
      "them)");
  return {cmd, [flags] { return RunSampleMany(*flags); }};
}

int RunSampleMany(const SampleManyFlags& flags) {
  Job job;
  job.flags = &flags;
  if (flags.format == "npy") {
    job.format = OutputFormat::kNpy;
  } else if (flags.format == "csv") {
    job.format = OutputFormat::kCsv;
  } else if (flags.format == "ply") {
    job.format = flags.ascii ? OutputFormat::kPlyAscii : OutputFormat::kPlyBinary;
  } else {
    return Usage("--format must be npy, csv or ply");
  }
  const auto precision = ParseColumnPrecision(flags.precision);
  if (!precision.ok()) return Usage(std::string(precision.status().message()));
  job.precision = *precision;
  {  // the shared flags, checked once on a stand-in surface
    RequestFlags probe = flags.request;
    probe.surface = "sphere";
    auto checked = ToSampleRequest(probe);
    if (!checked.ok()) return Usage(std::string(checked.status().message()));
    if (auto s = SampleWriter::CheckColumns(job.format, checked->fields, flags.columns); !s.ok()) {
      return Usage(std::string(s.message()));
    }
  }
  std::vector<Outcome> outcomes;
  for (const std::string& input : flags.inputs) {
    auto paths = Expand(input);
    if (!paths.ok()) return Usage(std::string(paths.status().message()));
    for (Named& p : *paths) {
      outcomes.emplace_back();
      outcomes.back().path = std::move(p.path);
      outcomes.back().name = std::move(p.name);
    }
  }
  if (outcomes.empty()) return Usage("the inputs name no models");
  std::error_code error;
  fs::create_directories(flags.out_dir, error);
  if (error) return Usage(absl::StrFormat("cannot create %s: %s", flags.out_dir, error.message()));
  // Outputs mirror the names under --output-dir; models that share a stem
  // keep their extensions; a name given twice is refused.
  std::map<std::string, int> stems;
  for (const Outcome& o : outcomes) ++stems[OutputName(o.name, flags.format, false)];
  std::map<std::string, std::string> by_output;
  for (Outcome& o : outcomes) {
    const bool clash = stems[OutputName(o.name, flags.format, false)] > 1;
    o.output = (fs::path(flags.out_dir) / OutputName(o.name, flags.format, clash)).string();
    auto [it, fresh] = by_output.emplace(o.output, o.path);
    if (!fresh) {
      return Usage(absl::StrFormat("%s and %s would both write %s; name each model once",
                                   it->second, o.path, o.output));
    }
  }

  const unsigned hardware = std::max(1u, std::thread::hardware_concurrency());
  const size_t jobs =
      std::min<size_t>(outcomes.size(), flags.jobs > 0 ? flags.jobs : std::min(8u, hardware));
  SampleSourceOptions options;
  options.precision = job.precision;
  // Models run side by side; one model alone may use up to four threads.
  options.generation_threads = jobs > 1 ? 1 : 0;
  if (absl::Status read = ApplyModelReadFlags(flags.model_read, &options); !read.ok()) {
    return Usage(std::string(read.message()));
  }
  auto source = OpenSampleSource(flags.connection, options);
  if (!source.ok()) return Usage(std::string(source.status().message()));
  job.source = source->get();

  const auto start = std::chrono::steady_clock::now();
  Bar bar(outcomes.size(), !flags.quiet);
  std::atomic<size_t> next{0};
  std::vector<std::thread> workers;
  for (size_t w = 0; w < jobs; ++w) {
    workers.emplace_back([&] {
      for (size_t i; (i = next.fetch_add(1)) < outcomes.size();) {
        Outcome& o = outcomes[i];
        const auto t0 = std::chrono::steady_clock::now();
        const absl::Status status = SampleOne(job, &o);
        o.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        o.done = status.ok();
        if (!status.ok()) {
          o.error =
              absl::StrFormat("%s: %s", absl::StatusCodeToString(status.code()), status.message());
          o.samples = 0;
        }
        bar.Step(!status.ok(), o.samples);
      }
    });
  }
  for (auto& t : workers) t.join();
  bar.Clear();
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  size_t failed = 0;
  uint64_t samples = 0;
  for (const Outcome& o : outcomes) {
    failed += !o.done;
    samples += o.samples;
  }
  if (!flags.manifest.empty()) {
    std::ofstream tsv(flags.manifest);
    tsv << "name\tsha256\tseed\tsamples\toutput\terror\n";
    for (const Outcome& o : outcomes) {
      std::string message = o.error;
      std::replace(message.begin(), message.end(), '\t', ' ');
      std::replace(message.begin(), message.end(), '\n', ' ');
      tsv << o.name << '\t' << o.sha256 << '\t' << o.seed << '\t' << o.samples << '\t'
          << (o.done ? o.output : "") << '\t' << message << '\n';
    }
    if (!tsv)
      std::fprintf(stderr, "sfcsampler sample-many: cannot write %s\n", flags.manifest.c_str());
  }
  if (!flags.quiet) {
    std::fprintf(stderr,
                 "sample-many: %zu models, %zu written to %s, %zu failed; %llu samples in %.3f s "
                 "(%zu at once)\n",
                 outcomes.size(), outcomes.size() - failed, flags.out_dir.c_str(), failed,
                 static_cast<unsigned long long>(samples), seconds, jobs);
  }
  for (const Outcome& o : outcomes) {
    if (!o.done) std::fprintf(stderr, "FAILED %s: %s\n", o.name.c_str(), o.error.c_str());
  }
  return failed ? 1 : 0;
}

}  // namespace sfc
