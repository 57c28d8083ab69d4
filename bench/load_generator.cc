// Load and soak generator for a running sfcsampler-server (tools/soak.sh
// starts one and runs this against it). N worker threads each loop until the
// time is up, picking one scenario per stream:
//   complete    a valid request (built-in and expr: surfaces, densities,
//               counts, sequences, index ranges, shards, regions) read to the
//               end through the client library; the sample count must be the
//               expected one, and one stream in --check-every is compared
//               bit for bit with an in-process run of the same request;
//   cancel      a large request cancelled after a few messages: CANCELLED;
//   slow        a reader that takes one message every --slow-read-seconds,
//               then cancels; the server may cut it first (its write
//               timeout): OK, CANCELLED or DEADLINE_EXCEEDED;
//   deadline    a large request with a short client deadline:
//               DEADLINE_EXCEEDED (or OK if it beat the deadline);
//   bad         a request outside a limit or malformed: INVALID_ARGUMENT or
//               RESOURCE_EXHAUSTED as the request deserves.
// With --model-share P, P % of the workers run the model phase instead
// (bench/soak_models.h writes the models into --model-dir):
//   model       a good model (the CAD fixtures as STEP, IGES, NURBS;
//               icosphere meshes as OBJ and PLY) sampled by file path, so the
//               client library uploads it when the server lacks it; checked
//               like complete (one in --check-every against an in-process
//               run reading the same file);
//   large model the same with a mesh of 1.3 M triangles (tens of MB parsed),
//               which pushes the parsed-model budget;
//   hostile     an upload the server must refuse, at the upload or at its
//               first Sample: INVALID_ARGUMENT or RESOURCE_EXHAUSTED;
//   unknown     a Sample naming a hash the server never stored: NOT_FOUND.
// A model evicted from the server's store between its upload and its stream
// (NOT_FOUND) is uploaded again, up to 3 times; counted apart.
// In every scenario a RESOURCE_EXHAUSTED naming the build queue
// (max_queued_builds), the parse queue (max_queued_parses) or the tree memory
// of the builds under way ("(cache_bytes): retry later") is the server
// shedding load: expected, and counted;
// the worker then backs off for 0.25-1 s, as a client told to retry later.
// Every outcome is classified expected or unexpected. A sampler thread reads
// the server's VmRSS and VmHWM from /proc/PID/status. At the end it prints a
// table and exits 1 if anything unexpected happened.
//
//   load_generator --server 127.0.0.1:PORT --server-pid PID [--streams 64]
//                  [--seconds 60] [--seed 1] [--slow-read-seconds 3]
//                  [--stream-deadline 60] [--model-share 0 --model-dir DIR]
// --seconds is when workers stop starting streams; the streams under way
// then finish (a complete stream within --stream-deadline).
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cinttypes>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "CLI/CLI.hpp"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/synchronization/mutex.h"
#include "bench/soak_models.h"
#include "client/sampler_client.h"
#include "engine/model_source.h"
#include "engine/sampling_engine.h"
#include "grpcpp/client_context.h"
#include "grpcpp/create_channel.h"
#include "kinds/registered_kinds.h"
#include "proto/convert.h"
#include "request/index_range.h"
#include "request/routing_key.h"

namespace sfc {
namespace {

namespace v1 = ::sfcsampler::v1;
using Clock = std::chrono::steady_clock;

struct Flags {
  std::string server = "127.0.0.1:50051";
  int server_pid = 0;
  int streams = 64;
  double seconds = 60;
  uint64_t seed = 1;
  double slow_read_seconds = 3;
  int slow_reads = 4;       // messages a slow reader takes before it cancels
  int check_every = 4;      // compare one completed stream in this many in-process
  uint32_t batch_size = 8192;
  double stream_deadline_seconds = 60;  // a complete stream that takes longer is unexpected
  int model_share = 0;         // percent of workers in the model phase
  std::string model_dir;       // where the model phase writes its models
  int large_subdivisions = 8;  // the large meshes' icosphere subdivisions
};

// What the server will hold requests to (from GetCacheStats).
struct ServerLimits {
  uint64_t max_count = 0, max_tree_leaves = 0, max_spec_length = 0, max_sorted_range = 0;
  uint64_t budget_bytes = 0;         // trees (cache_bytes)
  uint64_t stream_memory_bytes = 0;  // streams' working memory
  uint64_t model_budget_bytes = 0;   // uploaded models kept (model_bytes)
  uint64_t parsed_model_budget_bytes = 0;  // parsed models kept (parsed_model_bytes)
  uint64_t parse_memory_bytes = 0;  // working memory of running parses (0: none set)
  uint32_t max_concurrent_streams = 0;
};

const char* const kSurfaces[] = {
    "sphere",
    "torus:R=2;r=0.5",
    "plane",
    "eight",
    "monkey_saddle",
    "whitney",
    "superellipsoid:e=1/3;reparam=1",
    "expr:x=u;y=v;z=0.3*sin(6*u)*cos(4*v)",
    "expr:x=cos(u)*cos(v);y=cos(u)*sin(v);z=sin(u);u0=-_pi/2;u1=_pi/2;v0=-_pi;v1=_pi",
};
const char* const kDensities[] = {"uniform", "gaussian:floor=0.05", "mean:floor=0.1",
                                  "expr:0.1+u*v", "expr:1+x*x"};

// Outcome counters, shared by the workers.
class Tally {
 public:
  void Started() { started_.fetch_add(1, std::memory_order_relaxed); }
  void Samples(uint64_t n) { samples_.fetch_add(n, std::memory_order_relaxed); }
  // A request the server turned away because its build queue was full is
  // load shedding, which a client retries later: expected in every scenario.
  // Returns true for such a request, after which the worker backs off.
  bool Outcome(const std::string& scenario, grpc::StatusCode code, bool expected,
               const std::string& detail) {
    absl::MutexLock lock(&mu_);
    ++by_code_[code];
    ++by_scenario_[scenario];
    if (code == grpc::StatusCode::OK) ++completed_;
    const bool shed = code == grpc::StatusCode::RESOURCE_EXHAUSTED &&
                      (detail.find("max_queued_builds") != std::string::npos ||
                       detail.find("max_queued_parses") != std::string::npos);
    const bool shed_for_memory = code == grpc::StatusCode::RESOURCE_EXHAUSTED &&
                                 detail.find("(cache_bytes): retry later") != std::string::npos;
    if (shed || shed_for_memory) {
      ++(shed ? shed_ : shed_for_memory_);
      expected = true;
    }
    if (!expected) {
      ++unexpected_;
      ++unexpected_by_[absl::StrFormat("%s, %s", scenario, CodeName(code))];
      if (examples_.size() < 10) {
        examples_.push_back(
            absl::StrFormat("%s: code %d: %s", scenario, static_cast<int>(code), detail));
      }
    }
    return shed || shed_for_memory;
  }
  void Evicted() {
    absl::MutexLock lock(&mu_);
    ++evicted_;
  }
  void Checked(bool same) {
    absl::MutexLock lock(&mu_);
    ++checked_;
    if (!same) ++check_mismatches_;
  }

  uint64_t started() const { return started_.load(); }
  uint64_t samples() const { return samples_.load(); }

  void Print(double seconds, const ServerLimits& limits, uint64_t peak_rss, uint64_t hwm) const {
    absl::MutexLock lock(&mu_);
    std::printf("| measurement | value | target |\n|---|---:|---:|\n");
    std::printf("| streams started | %" PRIu64 " | |\n", started_.load());
    std::printf("| streams completed (OK, counts verified) | %" PRIu64 " | |\n", completed_);
    for (const auto& [code, n] : by_code_) {
      std::printf("| status %s | %" PRIu64 " | |\n", CodeName(code), n);
    }
    std::printf(
        "| of which RESOURCE_EXHAUSTED for a full build or parse queue (load shed) | %" PRIu64
        " | |\n",
        shed_);
    std::printf(
        "| of which RESOURCE_EXHAUSTED for the tree memory of builds under way (load shed) | "
        "%" PRIu64 " | |\n",
        shed_for_memory_);
    std::printf("| model streams that met their model evicted, uploaded again | %" PRIu64 " | |\n",
                evicted_);
    for (const auto& [scenario, n] : by_scenario_) {
      std::printf("| scenario %s | %" PRIu64 " | |\n", scenario.c_str(), n);
    }
    std::printf("| completed streams compared with an in-process run | %" PRIu64 " | |\n",
                checked_);
    std::printf("| of those not byte-identical | %" PRIu64 " | 0 |\n", check_mismatches_);
    std::printf("| unexpected outcomes | %" PRIu64 " | 0 |\n", unexpected_);
    for (const auto& [what, n] : unexpected_by_) {
      std::printf("| unexpected: %s | %" PRIu64 " | 0 |\n", what.c_str(), n);
    }
    std::printf("| samples received | %" PRIu64 " | |\n", samples_.load());
    std::printf("| samples/s (all streams, %.0f s) | %.3g | |\n", seconds,
                samples_.load() / seconds);
    const double mib = 1024.0 * 1024.0;
    // The server's memory budgets: trees, streams' working memory, uploaded
    // models (stored and being received), parsed models and parses' working
    // memory.
    const double budget = limits.budget_bytes + limits.stream_memory_bytes +
                          limits.model_budget_bytes + limits.parsed_model_budget_bytes +
                          limits.parse_memory_bytes;
    std::printf(
        "| server memory budgets: cache + stream memory + models + parsed models + parse memory | "
        "%.1f + %.1f + %.1f + %.1f + %.1f = %.1f MiB | |\n",
        limits.budget_bytes / mib, limits.stream_memory_bytes / mib,
        limits.model_budget_bytes / mib, limits.parsed_model_budget_bytes / mib,
        limits.parse_memory_bytes / mib, budget / mib);
    std::printf("| server peak VmRSS (sampled every 100 ms) | %.1f MiB | <= %.1f MiB |\n",
                peak_rss / mib, 1.2 * budget / mib);
    std::printf("| server VmHWM at the end | %.1f MiB | <= %.1f MiB |\n", hwm / mib,
                1.2 * budget / mib);
    for (const std::string& e : examples_) std::printf("unexpected: %s\n", e.c_str());
  }
  uint64_t unexpected() const {
    absl::MutexLock lock(&mu_);
    return unexpected_ + check_mismatches_;
  }

  static const char* CodeName(grpc::StatusCode code) {
    switch (code) {
      case grpc::StatusCode::OK: return "OK";
      case grpc::StatusCode::CANCELLED: return "CANCELLED";
      case grpc::StatusCode::INVALID_ARGUMENT: return "INVALID_ARGUMENT";
      case grpc::StatusCode::NOT_FOUND: return "NOT_FOUND";
      case grpc::StatusCode::FAILED_PRECONDITION: return "FAILED_PRECONDITION";
      case grpc::StatusCode::DEADLINE_EXCEEDED: return "DEADLINE_EXCEEDED";
      case grpc::StatusCode::RESOURCE_EXHAUSTED: return "RESOURCE_EXHAUSTED";
      case grpc::StatusCode::UNAVAILABLE: return "UNAVAILABLE";
      case grpc::StatusCode::INTERNAL: return "INTERNAL";
      case grpc::StatusCode::DATA_LOSS: return "DATA_LOSS";
      case grpc::StatusCode::UNKNOWN: return "UNKNOWN";
      default: return "other";
    }
  }

 private:
  std::atomic<uint64_t> started_{0}, samples_{0};
  mutable absl::Mutex mu_;
  std::map<grpc::StatusCode, uint64_t> by_code_ ABSL_GUARDED_BY(mu_);
  std::map<std::string, uint64_t> by_scenario_ ABSL_GUARDED_BY(mu_);
  uint64_t completed_ ABSL_GUARDED_BY(mu_) = 0;
  uint64_t shed_ ABSL_GUARDED_BY(mu_) = 0;
  uint64_t shed_for_memory_ ABSL_GUARDED_BY(mu_) = 0;
  uint64_t evicted_ ABSL_GUARDED_BY(mu_) = 0;
  std::map<std::string, uint64_t> unexpected_by_ ABSL_GUARDED_BY(mu_);  // "scenario, CODE"
  uint64_t unexpected_ ABSL_GUARDED_BY(mu_) = 0;
  uint64_t checked_ ABSL_GUARDED_BY(mu_) = 0;
  uint64_t check_mismatches_ ABSL_GUARDED_BY(mu_) = 0;
  std::vector<std::string> examples_ ABSL_GUARDED_BY(mu_);
};

grpc::StatusCode ToGrpcCode(absl::StatusCode code) { return static_cast<grpc::StatusCode>(code); }

// A valid request whose size the stream can finish in well under a second or
// two on a shared machine.
SampleRequest ValidRequest(std::mt19937_64& rng) {
  auto pick = [&](auto& list) { return list[rng() % std::size(list)]; };
  SampleRequest r;
  r.tree.surface = pick(kSurfaces);
  r.tree.density = pick(kDensities);
  // Mostly the default tree options, as most jobs use them, so that trees
  // get shared; the other curves and the quadrature estimator now and then.
  const CurveType curves[] = {CurveType::kHilbert, CurveType::kHilbert, CurveType::kHilbert,
                              CurveType::kHilbert2, CurveType::kPeano};
  r.tree.options.curve = pick(curves);
  if (rng() % 8 == 0) r.tree.options.estimator = AreaEstimator::kQuadrature;
  const uint64_t counts[] = {1000, 10000, 50000, 100000};
  r.count = pick(counts);
  r.seed = rng() % 5;  // few seeds: trees (keyed without the seed) get shared
  switch (rng() % 6) {
    case 0: r.sequence = SequenceKind::kProgressive; break;
    case 1: r.sequence = SequenceKind::kRandom; break;
    case 2: r.sequence = SequenceKind::kEqual; break;
    default: r.sequence = SequenceKind::kJittered; break;
  }
  switch (rng() % 5) {
    case 0: {  // an index range
      const uint64_t a = rng() % r.count, b = rng() % r.count;
      r.begin = std::min(a, b);
      r.end = std::max(a, b) + 1;
      break;
    }
    case 1:  // a shard
      r.shard_count = 1 + rng() % 16;
      r.shard_index = rng() % r.shard_count;
      break;
    case 2: {  // a parameter rectangle
      const double u0 = (rng() % 50) / 100.0, v0 = (rng() % 50) / 100.0;
      r.region = Region::ParameterRect(u0, u0 + 0.25, v0, v0 + 0.5);
      break;
    }
    case 3:  // a 3D box around the origin's positive octant
      r.region = Region::Box({0, 0, 0}, {1, 1, 1});
      break;
    default: break;
  }
  r.fields.normal = rng() % 3 == 0;
  r.fields.density = rng() % 4 == 0;
  r.fields.curve_position = rng() % 4 == 0;
  return r;
}

// A large request for the cancel, slow and deadline scenarios.
SampleRequest LongRequest(std::mt19937_64& rng) {
  SampleRequest r;
  r.tree.surface = kSurfaces[rng() % 3];
  r.count = 2'000'000;
  r.seed = rng() % 5;
  r.tree.options.rho = 8;  // a coarse tree (about 0.7 M leaves): cheap to build and cache
  return r;
}

struct BadCase {
  SampleRequest request;
  grpc::StatusCode expected;
  const char* what;
};

BadCase BadRequest(std::mt19937_64& rng, const ServerLimits& limits) {
  SampleRequest r;
  r.count = 1000;
  auto invalid = [&](const char* what) {
    return BadCase{r, grpc::StatusCode::INVALID_ARGUMENT, what};
  };
  // The tree-budget case builds up to max_tree_leaves before it fails, so it
  // is rare (one bad request in 50); the others fail before any build.
  switch (rng() % 50 == 0 ? 10 : rng() % 10) {
    case 0: r.tree.surface = "klein"; return invalid("unknown surface");
    case 1: r.count = 0; return invalid("count 0");
    case 2: r.count = limits.max_count + 1; return invalid("a whole set above max_count");
    case 3: r.begin = 500, r.end = 100; return invalid("begin > end");
    case 4: r.shard_index = 3, r.shard_count = 3; return invalid("shard index >= shard count");
    case 5: r.region = Region::ParameterRect(0.5, 0.5, 0, 1); return invalid("empty region");
    case 6: r.tree.surface = "expr:x=u;y=v;z=sin(u"; return invalid("expression syntax");
    case 7: r.tree.surface = "expr:x=sqrt(u-2);y=v;z=0"; return invalid("surface NaN");
    case 8: r.tree.density = "expr:-1"; return invalid("negative density");
    case 9:
      r.tree.surface = "expr:x=u;y=v;z=" + std::string(limits.max_spec_length, '1');
      return invalid("spec too long");
    default:
      // A tree that needs more leaves than the server allows: a pole the tree
      // refines towards until its budget, asked for max_count samples.
      r.count = limits.max_count;
      r.tree.surface = "expr:x=u;y=v;z=1/(u-0.3)";
      return BadCase{r, grpc::StatusCode::RESOURCE_EXHAUSTED, "tree above max_tree_leaves"};
  }
}

class Worker {
 public:
  Worker(const Flags& flags, const ServerLimits& limits, Tally* tally, SamplerClient* client,
         v1::Sampler::Stub* stub, const SamplingEngine* engine, uint64_t seed,
         const SoakModels* models = nullptr, const SamplingEngine* model_engine = nullptr)
      : flags_(flags),
        limits_(limits),
        tally_(tally),
        client_(client),
        stub_(stub),
        engine_(engine),
        models_(models),
        model_engine_(model_engine),
        rng_(seed) {}

  // Formula scenarios, or with `models` the model phase's.
  void Run(Clock::time_point stop) {
    while (Clock::now() < stop) {
      const int roll = static_cast<int>(rng_() % 100);
      tally_->Started();
      if (models_ != nullptr) {
        if (roll < 60) {
          Model("model", models_->good()[rng_() % models_->good().size()]);
        } else if (roll < 68) {
          Model("large model", models_->large()[rng_() % models_->large().size()]);
        } else if (roll < 95) {
          Hostile();
        } else {
          Unknown();
        }
      } else if (roll < 55) {
        Complete();
      } else if (roll < 70) {
        Cancel();
      } else if (roll < 75) {
        Slow();
      } else if (roll < 82) {
        Deadline();
      } else {
        Bad();
      }
      if (shed_) {
        // "Retry later": a well-behaved client backs off for 0.25-1 s.
        shed_ = false;
        std::this_thread::sleep_for(std::chrono::milliseconds(250 + rng_() % 750));
      }
    }
  }

 private:
  void Report(const std::string& scenario, grpc::StatusCode code, bool expected,
              const std::string& detail) {
    shed_ = tally_->Outcome(scenario, code, expected, detail);
  }

  void Complete() {
    const SampleRequest request = ValidRequest(rng_);
    SampleBatch received;
    const bool check = (++completes_ % flags_.check_every) == 0;
    auto summary = client_->Sample(request, [&](const StreamInfo&, const SampleBatch& b) {
      tally_->Samples(b.size());
      if (check) received.Append(b);
      return absl::OkStatus();
    });
    if (!summary.ok()) {
      Report("complete", ToGrpcCode(summary.status().code()), false,
                      std::string(summary.status().message()));
      return;
    }
    // Without a region the count is known; the client library already checked
    // it against the header and the server's trailer, check it here again.
    const auto range = ResolveIndexRange(request);
    if (request.region.kind == Region::Kind::kAll &&
        summary->received != range->second - range->first) {
      Report("complete", grpc::StatusCode::DATA_LOSS, false,
                      absl::StrFormat("received %d of %d samples", summary->received,
                                      range->second - range->first));
      return;
    }
    Report("complete", grpc::StatusCode::OK, true, "");
    if (check) tally_->Checked(SameAsInProcess(*engine_, request, received));
  }

  // A request for `model`, sampled by its file's path (the client library
  // uploads it if the server lacks it), its count checked; one in
  // --check-every compared with an in-process run reading the same file.
  void Model(const std::string& scenario, const SoakModel& model) {
    SampleRequest request;
    request.tree.surface = model.spec;
    const char* const densities[] = {"uniform", "uniform", "expr:1+x*x", "expr:0.5+z*z"};
    request.tree.density = densities[rng_() % std::size(densities)];
    const uint64_t counts[] = {1000, 10000, 50000};
    request.count = counts[rng_() % std::size(counts)];
    request.seed = rng_() % 3;
    request.sequence = rng_() % 3 == 0 ? SequenceKind::kRandom : SequenceKind::kJittered;
    if (rng_() % 4 == 0) {
      request.shard_count = 1 + rng_() % 8;
      request.shard_index = rng_() % request.shard_count;
    }
    request.fields.normal = rng_() % 2 == 0;
    request.fields.face = model.cad && rng_() % 2 == 0;
    request.fields.triangle = !model.cad && rng_() % 2 == 0;
    const bool check = (++completes_ % flags_.check_every) == 0;
    SampleBatch received;
    absl::StatusOr<StreamSummary> summary;
    for (int attempt = 0; attempt < 4; ++attempt) {
      received = SampleBatch();
      summary = client_->Sample(request, [&](const StreamInfo&, const SampleBatch& b) {
        tally_->Samples(b.size());
        if (check) received.Append(b);
        return absl::OkStatus();
      });
      // Evicted from the store between the client's upload and the stream:
      // the next Sample uploads it again.
      if (summary.ok() || summary.status().code() != absl::StatusCode::kNotFound) break;
      tally_->Evicted();
    }
    if (!summary.ok()) {
      Report(scenario, ToGrpcCode(summary.status().code()), false,
             absl::StrCat(model.spec, ": ", summary.status().message()));
      return;
    }
    const auto range = ResolveIndexRange(request);
    if (summary->received != range->second - range->first) {
      Report(scenario, grpc::StatusCode::DATA_LOSS, false,
             absl::StrFormat("%s: received %d of %d samples", model.spec, summary->received,
                             range->second - range->first));
      return;
    }
    Report(scenario, grpc::StatusCode::OK, true, "");
    if (check) tally_->Checked(SameAsInProcess(*model_engine_, request, received));
  }

  // An upload the server must refuse, at the upload or at the first Sample
  // of it (INVALID_ARGUMENT or RESOURCE_EXHAUSTED, with a message).
  void Hostile() {
    const HostileUpload upload = models_->Hostile(rng_);
    const std::string scenario = absl::StrFormat("hostile (%s)", upload.what);
    auto refused = [](absl::StatusCode code) {
      return code == absl::StatusCode::kInvalidArgument ||
             code == absl::StatusCode::kResourceExhausted;
    };
    auto info = client_->UploadModel(upload.format, upload.name, upload.bytes);
    if (!info.ok()) {
      Report(scenario, ToGrpcCode(info.status().code()),
             refused(info.status().code()) && !info.status().message().empty(),
             std::string(info.status().message()));
      return;
    }
    SampleRequest request;
    request.tree.surface = info->spec();
    request.count = 1000;
    uint64_t got = 0;
    auto summary = client_->Sample(request, [&](const StreamInfo&, const SampleBatch& b) {
      got += b.size();
      return absl::OkStatus();
    });
    if (summary.ok()) {
      Report(scenario, grpc::StatusCode::OK, false,
             absl::StrFormat("%s accepted (%d samples)", upload.what, got));
      return;
    }
    // Evicted before its Sample: neither accepted nor refused; counted apart.
    if (summary.status().code() == absl::StatusCode::kNotFound) {
      tally_->Evicted();
      Report(scenario, grpc::StatusCode::NOT_FOUND, true, "");
      return;
    }
    Report(scenario, ToGrpcCode(summary.status().code()),
           refused(summary.status().code()) && got == 0 && !summary.status().message().empty(),
           std::string(summary.status().message()));
  }

  // A model hash the server never stored: NOT_FOUND.
  void Unknown() {
    SampleRequest request;
    request.tree.surface = "ply:sha256=" + std::string(63, 'a') + "0123456789abcdef"[rng_() % 16];
    request.count = 1000;
    auto summary = client_->Sample(
        request, [](const StreamInfo&, const SampleBatch&) { return absl::OkStatus(); });
    const absl::StatusCode code = summary.ok() ? absl::StatusCode::kOk : summary.status().code();
    Report("unknown model", ToGrpcCode(code), code == absl::StatusCode::kNotFound,
           summary.ok() ? "" : std::string(summary.status().message()));
  }

  // Runs `request` in `engine` in this process and compares every column bit
  // for bit.
  static bool SameAsInProcess(const SamplingEngine& engine, const SampleRequest& request,
                              const SampleBatch& wire) {
    auto job = engine.Start(request);
    if (!job.ok()) return false;
    SampleBatch local;
    for (;;) {
      auto n = job->cursor->Next(65536, &local);
      if (!n.ok()) return false;
      if (*n == 0) break;
    }
    auto same = [](const std::vector<double>& a, const std::vector<double>& b) {
      return a.size() == b.size() &&
             (a.empty() || std::memcmp(a.data(), b.data(), a.size() * 8) == 0);
    };
    return local.index == wire.index && same(local.u, wire.u) && same(local.v, wire.v) &&
           same(local.x, wire.x) && same(local.y, wire.y) && same(local.z, wire.z) &&
           same(local.nx, wire.nx) && same(local.ny, wire.ny) && same(local.nz, wire.nz) &&
           same(local.density, wire.density) && same(local.curve_position, wire.curve_position) &&
           local.face == wire.face && local.triangle == wire.triangle;
  }

  // Opens a raw stream (no client-library resume, so the server's own status
  // code is what we see).
  std::unique_ptr<grpc::ClientReader<v1::SampleResponse>> Open(grpc::ClientContext* context,
                                                              const SampleRequest& request,
                                                              uint32_t batch_size) {
    v1::SampleRequest wire = ToProto(request);
    wire.set_batch_size(batch_size);
    context->AddMetadata("x-surface-key", RoutingKey(request.tree));
    return stub_->Sample(context, wire);
  }

  uint64_t Count(const v1::SampleResponse& r) {
    const uint64_t n = r.batch().size();
    tally_->Samples(n);
    return n;
  }

  void Cancel() {
    grpc::ClientContext context;
    auto reader = Open(&context, LongRequest(rng_), flags_.batch_size);
    v1::SampleResponse response;
    const int reads = 1 + static_cast<int>(rng_() % 5);
    for (int i = 0; i < reads && reader->Read(&response); ++i) Count(response);
    context.TryCancel();
    while (reader->Read(&response)) {
    }
    const grpc::Status status = reader->Finish();
    // A stream that ended before the cancel (OK) would mean a 2 M request
    // finished within a few reads: unexpected.
    Report("cancel", status.error_code(), status.error_code() == grpc::StatusCode::CANCELLED,
                    status.error_message());
  }

  void Slow() {
    grpc::ClientContext context;
    auto reader = Open(&context, LongRequest(rng_), 1000);
    v1::SampleResponse response;
    bool ended = false;
    for (int i = 0; i < flags_.slow_reads; ++i) {
      if (!reader->Read(&response)) {
        ended = true;
        break;
      }
      Count(response);
      std::this_thread::sleep_for(
          std::chrono::milliseconds(static_cast<int>(flags_.slow_read_seconds * 1000)));
    }
    if (!ended) context.TryCancel();
    while (reader->Read(&response)) {
    }
    const grpc::Status status = reader->Finish();
    const auto code = status.error_code();
    Report("slow", code,
                    code == grpc::StatusCode::OK || code == grpc::StatusCode::CANCELLED ||
                        code == grpc::StatusCode::DEADLINE_EXCEEDED,
                    status.error_message());
  }

  void Deadline() {
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() +
                         std::chrono::milliseconds(20 + rng_() % 200));
    auto reader = Open(&context, LongRequest(rng_), flags_.batch_size);
    v1::SampleResponse response;
    while (reader->Read(&response)) Count(response);
    const grpc::Status status = reader->Finish();
    const auto code = status.error_code();
    Report("deadline", code,
                    code == grpc::StatusCode::DEADLINE_EXCEEDED || code == grpc::StatusCode::OK,
                    status.error_message());
  }

  void Bad() {
    const BadCase bad = BadRequest(rng_, limits_);
    grpc::ClientContext context;
    auto reader = Open(&context, bad.request, flags_.batch_size);
    v1::SampleResponse response;
    uint64_t got = 0;
    while (reader->Read(&response)) got += Count(response);
    const grpc::Status status = reader->Finish();
    Report(absl::StrFormat("bad (%s)", bad.what), status.error_code(),
           status.error_code() == bad.expected && got == 0 && !status.error_message().empty(),
           status.error_message());
  }

  const Flags& flags_;
  const ServerLimits& limits_;
  Tally* const tally_;
  SamplerClient* const client_;
  v1::Sampler::Stub* const stub_;
  const SamplingEngine* const engine_;
  const SoakModels* const models_;              // null: formula scenarios
  const SamplingEngine* const model_engine_;   // reads model files, for the model checks
  std::mt19937_64 rng_;
  uint64_t completes_ = 0;
  bool shed_ = false;  // the last stream was turned away by a full build queue
};

// kB value of `field` ("VmRSS:") in /proc/PID/status, in bytes; 0 if absent.
uint64_t ProcStatusBytes(int pid, const char* field) {
  std::ifstream in(absl::StrFormat("/proc/%d/status", pid));
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind(field, 0) == 0) return std::stoull(line.substr(std::strlen(field))) * 1024;
  }
  return 0;
}

int Main(int argc, char** argv) {
  Flags flags;
  CLI::App app{"load_generator: concurrent mixed streams against an sfcsampler-server"};
  app.add_option("--server", flags.server, "HOST:PORT")->capture_default_str();
  app.add_option("--server-pid", flags.server_pid, "the server's pid, for its RSS (0 = none)");
  app.add_option("--streams", flags.streams, "concurrent streams")->capture_default_str();
  app.add_option("--seconds", flags.seconds, "how long to run")->capture_default_str();
  app.add_option("--seed", flags.seed, "seed of the scenario mix")->capture_default_str();
  app.add_option("--slow-read-seconds", flags.slow_read_seconds,
                 "a slow reader's pause between messages")
      ->capture_default_str();
  app.add_option("--slow-reads", flags.slow_reads, "messages a slow reader takes before it cancels")
      ->capture_default_str();
  app.add_option("--check-every", flags.check_every,
                 "compare one completed stream in this many with an in-process run")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--batch-size", flags.batch_size, "samples per message")->capture_default_str();
  app.add_option("--stream-deadline", flags.stream_deadline_seconds,
                 "client deadline of a complete stream, seconds (bounds the run)")
      ->capture_default_str();
  app.add_option("--model-share", flags.model_share,
                 "percent of the workers that upload and sample models (the model phase)")
      ->capture_default_str()
      ->check(CLI::Range(0, 100));
  app.add_option("--model-dir", flags.model_dir,
                 "an existing directory for the model phase's files")
      ->capture_default_str();
  app.add_option("--large-subdivisions", flags.large_subdivisions,
                 "subdivisions of the large icosphere meshes (8: 1.3 M triangles)")
      ->capture_default_str()
      ->check(CLI::Range(2, 9));
  CLI11_PARSE(app, argc, argv);
  const int model_workers = (flags.streams * flags.model_share + 50) / 100;
  if (model_workers > 0 && flags.model_dir.empty()) {
    std::fprintf(stderr, "load_generator: --model-share needs --model-dir\n");
    return 2;
  }

  ClientOptions options;
  options.target = flags.server;
  options.stream.batch_size = flags.batch_size;
  options.deadline_seconds = flags.stream_deadline_seconds;
  auto client = SamplerClient::Connect(options);
  if (!client.ok()) {
    std::fprintf(stderr, "load_generator: %s\n", std::string(client.status().message()).c_str());
    return 2;
  }
  auto stats = (*client)->GetCacheStats();
  if (!stats.ok()) {
    std::fprintf(stderr, "load_generator: GetCacheStats: %s\n",
                 std::string(stats.status().message()).c_str());
    return 2;
  }
  ServerLimits limits;
  limits.max_count = stats->max_count();
  limits.max_tree_leaves = stats->max_tree_leaves();
  limits.max_spec_length = stats->max_spec_length();
  limits.max_sorted_range = stats->max_sorted_range();
  limits.budget_bytes = stats->budget_bytes();
  limits.stream_memory_bytes = stats->stream_memory_bytes();
  limits.model_budget_bytes = stats->model_budget_bytes();
  limits.parsed_model_budget_bytes = stats->parsed_model_budget_bytes();
  limits.parse_memory_bytes = stats->parse_memory_bytes();
  limits.max_concurrent_streams = stats->max_concurrent_streams();

  // The in-process reference uses the server's limits, so both accept the
  // same requests; trees are built afresh.
  EngineLimits engine_limits;
  engine_limits.max_count = limits.max_count;
  engine_limits.max_tree_leaves = limits.max_tree_leaves;
  engine_limits.max_spec_length = limits.max_spec_length;
  engine_limits.max_sorted_range = limits.max_sorted_range;
  DirectTreeSource source;
  SamplingEngine engine(RegisteredSurfaceKinds(), engine_limits, &source);
  // The model phase's reference reads the same files the client uploads.
  FileModelSource files;
  SamplingEngine model_engine(RegisteredSurfaceKinds(), engine_limits, &source, &files);
  std::optional<SoakModels> models;
  if (model_workers > 0) {
    auto written = SoakModels::Write(flags.model_dir, flags.large_subdivisions);
    if (!written.ok()) {
      std::fprintf(stderr, "load_generator: %s\n", std::string(written.status().message()).c_str());
      return 2;
    }
    models = *std::move(written);
    std::string large;
    for (const SoakModel& m : models->large()) {
      large += absl::StrFormat(" %s %.1f MiB;", m.spec.substr(m.spec.rfind('/') + 1),
                               m.bytes / (1024.0 * 1024.0));
    }
    std::printf("model phase: %d of %d workers; %zu good models; large meshes:%s\n", model_workers,
                flags.streams, models->good().size(), large.c_str());
    std::fflush(stdout);
  }

  grpc::ChannelArguments args;
  args.SetMaxReceiveMessageSize(-1);
  auto stub = v1::Sampler::NewStub(
      grpc::CreateCustomChannel(flags.server, grpc::InsecureChannelCredentials(), args));

  Tally tally;
  std::atomic<bool> done{false};
  std::atomic<uint64_t> peak_rss{0};
  std::thread rss([&] {
    while (!done.load() && flags.server_pid > 0) {
      const uint64_t r = ProcStatusBytes(flags.server_pid, "VmRSS:");
      if (r > peak_rss.load()) peak_rss.store(r);
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
  });
  const auto start = Clock::now();
  const auto stop = start + std::chrono::milliseconds(static_cast<int64_t>(flags.seconds * 1000));
  std::vector<std::thread> workers;
  for (int i = 0; i < flags.streams; ++i) {
    workers.emplace_back([&, i] {
      const bool model_worker = i >= flags.streams - model_workers;
      Worker w(flags, limits, &tally, client->get(), stub.get(), &engine, flags.seed * 1000003 + i,
               model_worker ? &*models : nullptr, &model_engine);
      w.Run(stop);
    });
  }
  for (auto& t : workers) t.join();
  const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
  done.store(true);
  rss.join();
  const uint64_t hwm = flags.server_pid > 0 ? ProcStatusBytes(flags.server_pid, "VmHWM:") : 0;
  tally.Print(elapsed, limits, peak_rss.load(), hwm);
  return tally.unexpected() == 0 ? 0 : 1;
}

}  // namespace
}  // namespace sfc

int main(int argc, char** argv) { return sfc::Main(argc, argv); }
