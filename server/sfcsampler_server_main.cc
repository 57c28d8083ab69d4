// sfcsampler-server: serves sfcsampler.v1.Sampler over gRPC with a shared
// curve-tree cache. SIGTERM or SIGINT shuts it down gracefully: it stops
// accepting, lets in-flight streams finish within --shutdown-grace, then
// cancels them.
#include <signal.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iostream>

#include "CLI/CLI.hpp"
#include "absl/strings/str_format.h"
#include "absl/strings/strip.h"
#include "base/subprocess.h"
#include "core/blue_relaxation.h"
#include "core/curve_tree.h"
#include "kinds/registered_kinds.h"
#include "request/model_spec.h"
#include "server/memory_trimmer.h"
#include "server/sampler_server.h"
#include "spdlog/spdlog.h"

namespace {

// --model-check-program: "none" is "", "auto" the program next to this one
// (or "" when this build reads no CAD files), a path itself when it can run.
absl::Status ResolveModelCheckProgram(const std::string& flag, std::string* program) {
  const bool reads_cad =
      sfc::RegisteredSurfaceKinds().For(sfc::ModelSpec{sfc::ModelFormat::kStep}) != nullptr;
  if (flag == "none" || !reads_cad) {
    *program = "";
    return absl::OkStatus();
  }
  const absl::StatusOr<std::string> path = sfc::ResolveProgramFlag(flag, "sfcsampler-model-check");
  if (!path.ok() || path->empty()) {
    return absl::FailedPreconditionError(absl::StrFormat(
        "cannot run the model check program %s; install sfcsampler-model-check next to the server, "
        "name it with --model-check-program PATH, or pass --model-check-program none to read CAD "
        "files in process only",
        path.ok() ? "sfcsampler-model-check (not next to the server)" : flag));
  }
  *program = *path;
  return absl::OkStatus();
}

}  // namespace

int main(int argc, char** argv) {
  sfc::SetServerMallocOptions();
  sfc::ServerOptions o;
  int trim_interval_ms = 200;
  std::string token_file, log_level = "info";
  CLI::App app{"sfcsampler-server: density-controlled surface sampling over gRPC"};
  app.add_option("--address", o.address, "host:port of the sampler service")->capture_default_str();
  app.add_option("--health-address", o.health_address,
                 "host:port of a health-only listener without TLS or token (\"\" = none)")
      ->capture_default_str();
  app.add_option("--metrics-address", o.metrics_address,
                 "host:port of Prometheus /metrics (\"\" = none)")
      ->capture_default_str();
  app.add_option("--max-count", o.limits.max_count,
                 "samples one request delivers at most (its index range, shard or whole set)")
      ->capture_default_str();
  app.add_option("--max-set-count", o.limits.max_set_count, "largest N of a set")
      ->capture_default_str();
  app.add_option(
         "--max-tree-leaves", o.limits.max_tree_leaves,
         absl::StrFormat("largest tree, in leaves (%d bytes each)", sfc::CurveTree::kBytesPerLeaf))
      ->capture_default_str();
  app.add_option("--max-spec-length", o.limits.max_spec_length,
                 "longest surface or density spec, characters")
      ->capture_default_str();
  app.add_option("--max-sorted-range", o.limits.max_sorted_range,
                 "most samples per request for sequences sorted into curve order (random, "
                 "vandercorput, progressive), and the largest count of a sobol set (sorted "
                 "whole)")
      ->capture_default_str();
  app.add_option("--max-blue-count", o.limits.max_blue_count,
                 absl::StrFormat("largest N of the blue sequence (each request relaxes the whole "
                                 "set in memory, up to %d bytes a sample)",
                                 sfc::kBlueNoiseBytesPerSample))
      ->capture_default_str();
  app.add_option("--cache-bytes", o.cache_bytes, "tree cache budget in bytes (LRU eviction)")
      ->capture_default_str();
  app.add_option("--model-bytes", o.model_bytes, "uploaded models kept, bytes (LRU eviction)")
      ->capture_default_str();
  app.add_option("--max-model-bytes", o.max_model_bytes,
                 "largest model one upload may carry, bytes")
      ->capture_default_str();
  app.add_option("--parsed-model-bytes", o.limits.parsed_model_bytes,
                 "parsed models kept (meshes, CAD models), bytes (LRU eviction)")
      ->capture_default_str();
  app.add_option("--parse-memory-bytes", o.limits.parse_memory_bytes,
                 "working memory of the model parses running at once, bytes, estimated from each "
                 "file's size (about 30 bytes a byte of STEP or IGES, 32-64 of a mesh); a model "
                 "needing more is RESOURCE_EXHAUSTED (0: no limit)")
      ->capture_default_str();
  app.add_option("--model-parse-threads", o.limits.model_parse_threads,
                 "model files parsed at once (on threads of their own, not the RPC threads)")
      ->capture_default_str()
      ->check(CLI::Range(1, 64));
  app.add_option("--max-queued-parses", o.limits.max_queued_parses,
                 "model parses that may wait for a parse thread; more are RESOURCE_EXHAUSTED")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  app.add_option("--model-parse-seconds", o.limits.model_parse_seconds,
                 "CPU seconds one model parse may take before it is stopped (0: no limit); a "
                 "failed parse is remembered for --failure-ttl seconds")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  app.add_option("--model-parse-seconds-per-mib", o.limits.model_parse_seconds_per_mib,
                 "a CAD file's CPU budget is 2 s plus this much a MiB of file, at most "
                 "--model-parse-seconds (0: always --model-parse-seconds)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  app.add_option("--model-parse-fresh-seconds", o.limits.model_parse_fresh_seconds,
                 "how long a parse holds one of the --model-parse-threads slots; past it the parse "
                 "leaves its slot to the parses waiting and yields the CPU to them (0: it keeps "
                 "its slot to the end)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  app.add_option("--max-long-parses", o.limits.max_long_parses,
                 "parses running past --model-parse-fresh-seconds at once; one more is stopped "
                 "with RESOURCE_EXHAUSTED (retry later)")
      ->capture_default_str()
      ->check(CLI::Range(0, 64));
  app.add_option("--max-parse-queue-seconds", o.limits.max_parse_queue_seconds,
                 "longest a request waits for its model's parse to start (0: no limit)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  app.add_option("--max-concurrent-streams", o.max_concurrent_streams, "Sample streams at once")
      ->capture_default_str();
  app.add_option("--max-batch-size", o.max_batch_size, "most samples per message")
      ->capture_default_str();
  app.add_option("--max-message-bytes", o.max_message_bytes,
                 "largest message sent, bytes; batches are sized to fit (4 MiB: what stock gRPC "
                 "clients accept)")
      ->capture_default_str();
  app.add_option(
         "--stream-memory-bytes", o.stream_memory_bytes,
         "working memory of all streams together (sorting random/van der Corput/progressive "
         "ranges: 16 bytes a sample; batches and messages); streams wait for it")
      ->capture_default_str();
  app.add_option("--stream-pipeline-depth", o.stream_pipeline_depth,
                 "messages a stream generates ahead of its writes (it holds at most this + 2); 0: "
                 "generate between writes on the RPC thread")
      ->capture_default_str()
      ->check(CLI::Range(0, 16));
  app.add_option("--max-concurrent-builds", o.max_concurrent_builds, "tree builds at once")
      ->capture_default_str()
      ->check(CLI::Range(1, 64));
  app.add_option("--max-queued-builds", o.max_queued_builds,
                 "tree builds that may wait for a builder; a miss past that is RESOURCE_EXHAUSTED")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  app.add_option("--failure-ttl", o.failure_ttl_seconds,
                 "seconds a failed tree build is remembered (its error is returned at once)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  app.add_option("--write-timeout", o.write_timeout_seconds,
                 "seconds a stream may wait for a client that reads nothing before it is cut")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--upload-idle-timeout", o.upload_idle_timeout_seconds,
                 "seconds an UploadModel stream may send nothing before it is cut")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--upload-min-rate", o.upload_min_bytes_per_second,
                 "bytes a second an UploadModel stream must keep up after a grace of "
                 "--upload-idle-timeout seconds, or it is cut")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--generation-threads", o.limits.generation_threads,
                 "threads that fill one stream's batches (same samples, same order)")
      ->capture_default_str()
      ->check(CLI::Range(1, 64));
  app.add_option("--request-deadline", o.request_deadline_seconds,
                 "longest a stream may run, seconds")
      ->capture_default_str();
  app.add_option("--shutdown-grace", o.shutdown_grace_seconds,
                 "seconds in-flight streams get on SIGTERM before they are cancelled")
      ->capture_default_str();
  app.add_option("--tls-cert", o.tls_cert_file,
                 "PEM certificate chain; with --tls-key enables TLS");
  app.add_option("--tls-key", o.tls_key_file, "PEM private key");
  app.add_option(
      "--tls-client-ca", o.tls_client_ca_file,
      "PEM CA certificates; clients must present a certificate they signed (mutual TLS)");
  app.add_option("--token-file", token_file,
                 "file holding the bearer token every sampler RPC must carry");
  app.add_option("--trim-interval-ms", trim_interval_ms,
                 "how often freed heap memory is given back to the system (malloc_trim); 0 = never")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  std::string model_check = "auto";
  app.add_option(
         "--model-check-program", model_check,
         "reads each CAD file in a process of its own, where a crash or a loop in the CAD "
         "kernel costs one request, and makes the model of the shape it sends back (auto: "
         "sfcsampler-model-check next to this program; none: read CAD files in this process)")
      ->capture_default_str();
  app.add_option("--log-level", log_level, "trace | debug | info | warn | error")
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  if (absl::Status found = ResolveModelCheckProgram(model_check, &o.limits.model_check_program);
      !found.ok()) {
    std::cerr << "sfcsampler-server: " << found.message() << "\n";
    return 2;
  }

  spdlog::set_level(spdlog::level::from_str(log_level));
  sfc::MemoryTrimmer trimmer{std::chrono::milliseconds(trim_interval_ms)};
  if (!token_file.empty()) {
    std::ifstream in(token_file);
    std::string token((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    o.token = std::string(absl::StripAsciiWhitespace(token));
    if (!in || o.token.empty()) {
      std::cerr << "sfcsampler-server: cannot read a token from " << token_file << "\n";
      return 2;
    }
    if (o.tls_cert_file.empty()) spdlog::warn("a bearer token without TLS travels in clear text");
  }

  // Block the shutdown signals before gRPC starts its threads, then wait for
  // one on this thread.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGINT);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);

  auto server = sfc::SamplerServer::Start(o);
  if (!server.ok()) {
    std::cerr << "sfcsampler-server: " << server.status().message() << "\n";
    return 1;
  }
  int signal_number = 0;
  sigwait(&signals, &signal_number);
  spdlog::info("signal={} shutting down, grace={}s active_streams={}", signal_number,
               o.shutdown_grace_seconds, (*server)->service().active_streams());
  (*server)->Shutdown(o.shutdown_grace_seconds);
  spdlog::info("stopped");
  return 0;
}
