// Service benchmarks; prints a Markdown table. Everything runs in this
// process over loopback TCP: a real sfcsampler server, the C++ client
// library, and a raw-bytes gRPC stream as the baseline measured in the same
// run. To tell the stream's own cost from generation's, the same request is
// also timed in process (generation alone, the server's thread count) and
// through a bench-only service that streams the wire path without
// generating (one batch generated first, encoded into every message).
//   stream_benchmark [samples] [float32|float64] [--repeat=K [--raw]] [--glibc-malloc]
// samples defaults to 10^7; a precision runs that precision's stream rows
// only (no cache hits, no concurrent clients), for old-against-new rounds.
// --repeat=K instead streams that precision's pipelined raw-columns request
// (or with --raw the raw bytes) K times after one warm call, printing each
// time, for `perf stat` of that path alone. The process runs with the
// server's malloc settings (server/memory_trimmer.h SetServerMallocOptions),
// or glibc's defaults with --glibc-malloc (how this benchmark ran before).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "bench/raw_stream.grpc.pb.h"
#include "client/sampler_client.h"
#include "engine/sampling_engine.h"
#include "grpcpp/create_channel.h"
#include "grpcpp/server_builder.h"
#include "kinds/registered_kinds.h"
#include "proto/convert.h"
#include "server/memory_trimmer.h"
#include "server/sampler_server.h"

namespace sfc {
namespace {

namespace v1 = ::sfcsampler::v1;
using Clock = std::chrono::steady_clock;

double Since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

class RawStreamService final : public sfcsampler::bench::RawStream::Service {
  grpc::Status Stream(grpc::ServerContext*, const sfcsampler::bench::RawRequest* request,
                      grpc::ServerWriter<sfcsampler::bench::RawChunk>* writer) override {
    sfcsampler::bench::RawChunk chunk;
    chunk.mutable_data()->assign(request->chunk_bytes(), 'x');
    for (uint64_t sent = 0; sent < request->total_bytes(); sent += request->chunk_bytes()) {
      if (!writer->Write(chunk)) break;
    }
    return grpc::Status::OK;
  }
};

// The Sample RPC's wire path without generation: every message is encoded
// (ToProto, as the server does) from one batch generated beforehand, with
// its indices moved on, and written; the client decodes it as usual.
class WireOnlyService final : public v1::Sampler::Service {
 public:
  explicit WireOnlyService(SampleBatch batch) : batch_(std::move(batch)) {}
  grpc::Status Sample(grpc::ServerContext* context, const v1::SampleRequest* request,
                      grpc::ServerWriter<v1::SampleResponse>* writer) override {
    v1::SampleResponse response;
    response.mutable_header()->set_begin(0);
    response.mutable_header()->set_end(request->count());
    response.mutable_header()->set_expected_samples(static_cast<int64_t>(request->count()));
    const auto call = FromProto(*request);
    if (!call.ok()) return ToGrpcStatus(call.status());
    SampleBatch batch = batch_;
    for (uint64_t sent = 0; sent < request->count();) {
      const size_t n = std::min<uint64_t>(batch_.size(), request->count() - sent);
      if (n < batch.size()) batch = SampleBatch(), batch.AppendFrom(batch_, 0, n);
      for (size_t i = 0; i < n; ++i) batch.index[i] = sent + i;
      response.mutable_batch()->Clear();
      ToProto(batch, SampleFields{}, call->stream, response.mutable_batch());
      if (!writer->Write(response)) break;
      response.clear_header();
      sent += n;
    }
    return grpc::Status::OK;
  }

 private:
  const SampleBatch batch_;
};

// A plain gRPC server with `service` on a free loopback port, its address in `target`.
std::unique_ptr<grpc::Server> StartLoopback(grpc::Service* service, std::string* target) {
  grpc::ServerBuilder builder;
  int port = 0;
  builder.AddListeningPort("127.0.0.1:0", grpc::InsecureServerCredentials(), &port);
  builder.RegisterService(service);
  auto server = builder.BuildAndStart();
  *target = "127.0.0.1:" + std::to_string(port);
  return server;
}

// The fastest of `runs` calls of `seconds` (the machine is shared and noisy).
template <typename F>
double Best(F seconds, int runs = 2) {
  double best = seconds();
  for (int i = 1; i < runs; ++i) best = std::min(best, seconds());
  return best;
}

// Seconds to receive `total` bytes over a raw stream.
double RawSeconds(const std::string& target, uint64_t total, uint32_t chunk) {
  grpc::ChannelArguments args;
  args.SetMaxReceiveMessageSize(-1);
  auto stub = sfcsampler::bench::RawStream::NewStub(
      grpc::CreateCustomChannel(target, grpc::InsecureChannelCredentials(), args));
  grpc::ClientContext context;
  sfcsampler::bench::RawRequest request;
  request.set_total_bytes(total);
  request.set_chunk_bytes(chunk);
  const auto start = Clock::now();
  auto reader = stub->Stream(&context, request);
  sfcsampler::bench::RawChunk c;
  uint64_t got = 0;
  while (reader->Read(&c)) got += c.data().size();
  reader->Finish();
  return Since(start);
}

SampleRequest Request(const std::string& surface, const std::string& density, uint64_t n) {
  SampleRequest r;
  r.tree.surface = surface;
  r.tree.density = density;
  r.count = n;
  r.seed = 1;
  return r;
}

// A client of `target` that asks for columns of `precision` in batches of
// `batch`, encoded as `encoding`.
std::unique_ptr<SamplerClient> StreamClient(const std::string& target, ColumnPrecision precision,
                                            uint32_t batch, ColumnEncoding encoding) {
  ClientOptions co;
  co.target = target;
  co.stream.precision = precision;
  co.stream.batch_size = batch;
  co.stream.encoding = encoding;
  return *SamplerClient::Connect(co);
}

// Streams a request, touching every sample; returns seconds and bytes of payload.
double StreamSeconds(SamplerClient& client, const SampleRequest& request, uint64_t* received) {
  const auto start = Clock::now();
  double sink = 0;
  auto s = client.Sample(request, [&](const StreamInfo&, const SampleBatch& b) {
    for (size_t i = 0; i < b.size(); i += 4096) sink += b.x[i];
    return absl::OkStatus();
  });
  if (!s.ok()) {
    std::fprintf(stderr, "stream failed: %s\n", s.status().ToString().c_str());
    std::exit(1);
  }
  *received = s->received;
  if (sink == 12345.6789) std::printf(" ");
  return Since(start);
}

// Seconds to generate `request` in process from a tree built beforehand,
// in batches of `batch` with `threads` generation threads, as a server does.
double GenerationSeconds(const SampleRequest& request, int threads, uint32_t batch,
                         SampleBatch* first_batch = nullptr) {
  DirectTreeSource source;
  EngineLimits limits;
  limits.generation_threads = threads;
  limits.max_tree_leaves = uint64_t{1} << 26;
  SamplingEngine engine(RegisteredSurfaceKinds(), limits, &source);
  auto job = engine.Start(request);
  if (!job.ok()) {
    std::fprintf(stderr, "generation failed: %s\n", job.status().ToString().c_str());
    std::exit(1);
  }
  SampleBatch b;
  const auto start = Clock::now();
  for (bool first = true;; first = false) {
    b.Clear();
    if (*job->cursor->Next(batch, &b) == 0) break;
    if (first && first_batch) *first_batch = b;
  }
  return Since(start);
}

struct Args {
  uint64_t n = 10'000'000;
  std::string only;  // "float32", "float64" or empty (every row)
  int repeat = 0;
  bool raw = false;
  bool glibc_malloc = false;
};

int Run(const Args& args) {
  const uint64_t n = args.n;
  const std::string& only = args.only;
  // The server's process as sfcsampler-server runs it (its clients here
  // share the process and these settings).
  if (!args.glibc_malloc) SetServerMallocOptions();
  ServerOptions options;
  options.address = "127.0.0.1:0";
  options.health_address = "";
  options.metrics_address = "";
  options.limits.max_tree_leaves = uint64_t{1} << 26;
  auto server = *SamplerServer::Start(options);
  const std::string target = "127.0.0.1:" + std::to_string(server->port());
  ServerOptions unpipelined_options = options;
  unpipelined_options.stream_pipeline_depth = 0;
  auto unpipelined = *SamplerServer::Start(unpipelined_options);
  const std::string unpipelined_target = "127.0.0.1:" + std::to_string(unpipelined->port());

  RawStreamService raw;

  std::printf("| measurement | value |\n|---|---:|\n");
  const uint32_t batch = 65536;
  const SampleRequest sphere = Request("sphere", "uniform", n);
  SampleBatch one_batch;
  GenerationSeconds(Request("sphere", "uniform", batch), 1, batch, &one_batch);

  WireOnlyService wire_only(one_batch);
  std::string raw_target, wire_target;
  auto raw_server = StartLoopback(&raw, &raw_target);
  auto wire_server = StartLoopback(&wire_only, &wire_target);

  // Each stream next to the raw bytes and the generation it is bounded by.
  struct Case {
    const char* surface;
    const SampleRequest* request;
    ColumnPrecision precision;
  } cases[] = {{"sphere", &sphere, ColumnPrecision::kFloat32},
               {"sphere", &sphere, ColumnPrecision::kFloat64}};
  for (const Case& c : cases) {
    const ColumnPrecision precision = c.precision;
    if (!only.empty() && only != (precision == ColumnPrecision::kFloat32 ? "float32" : "float64"))
      continue;
    const SampleRequest& request = *c.request;
    const std::string label = std::string(c.surface) +
                              (precision == ColumnPrecision::kFloat32 ? ", float32" : ", float64");
    const char* name = label.c_str();
    const size_t value_bytes = precision == ColumnPrecision::kFloat32 ? 4 : 8;
    const uint64_t payload = n * 5 * value_bytes;
    if (args.repeat > 0) {
      auto client = StreamClient(target, precision, batch, ColumnEncoding::kRaw);
      uint64_t received = 0;
      StreamSeconds(*client, request, &received);  // builds and caches the tree
      for (int i = 0; i < args.repeat; ++i) {
        const double seconds = args.raw ? RawSeconds(raw_target, payload,
                                                     static_cast<uint32_t>(batch * 5 * value_bytes))
                                        : StreamSeconds(*client, request, &received);
        std::printf("%s %s: %.4f s\n", name, args.raw ? "raw bytes" : "stream", seconds);
      }
      continue;
    }
    const double raw_seconds = Best([&] {
      return RawSeconds(raw_target, payload, static_cast<uint32_t>(batch * 5 * value_bytes));
    });
    std::printf("| %s: raw bytes stream of the same %llu MB | %.0f MB/s |\n", name,
                static_cast<unsigned long long>(payload / 1000000), payload / raw_seconds / 1e6);
    // Measured next to the streams it explains (the machine's load drifts).
    const double generation =
        Best([&] { return GenerationSeconds(request, options.limits.generation_threads, batch); });
    std::printf(
        "| %s: generation alone, in process, the same %llu samples, %d threads | %.2f M samples/s "
        "|\n",
        name, static_cast<unsigned long long>(n), options.limits.generation_threads,
        n / generation / 1e6);
    // The stream as it ran before (generation between writes, packed
    // columns: a server with no pipeline), then pipelined with each encoding.
    struct Setup {
      const char* how;
      const std::string* target;
      ColumnEncoding encoding;
    } setups[] = {
        {"no pipeline, packed columns (as before)", &unpipelined_target, ColumnEncoding::kPacked},
        {"pipelined, packed columns", &target, ColumnEncoding::kPacked},
        {"pipelined, raw columns", &target, ColumnEncoding::kRaw}};
    for (const Setup& setup : setups) {
      auto client = StreamClient(*setup.target, precision, batch, setup.encoding);
      uint64_t received = 0;
      StreamSeconds(*client, request, &received);  // warm: build and cache the tree
      const double seconds = Best([&] { return StreamSeconds(*client, request, &received); });
      std::printf(
          "| %s, %s: %llu samples streamed (cached tree) | %.2f M samples/s (%.0f MB/s) |\n", name,
          setup.how, static_cast<unsigned long long>(received), received / seconds / 1e6,
          payload / seconds / 1e6);
      std::printf("| %s, %s: ratio stream / raw bytes; stream / generation alone | %.2f; %.2f |\n",
                  name, setup.how, raw_seconds / seconds, generation / seconds);
    }
    {
      // A client that keeps only the points leaves u and v off the wire
      // (SampleFields::uv): 3 columns a sample instead of 5.
      SampleRequest points = request;
      points.fields.uv = false;
      auto client = StreamClient(target, precision, batch, ColumnEncoding::kRaw);
      uint64_t received = 0;
      StreamSeconds(*client, points, &received);
      const double seconds = Best([&] { return StreamSeconds(*client, points, &received); });
      std::printf(
          "| %s, pipelined, raw columns, x y z only (omit_uv): %llu samples streamed | %.2f M "
          "samples/s (%.0f MB/s) |\n",
          name, static_cast<unsigned long long>(received), received / seconds / 1e6,
          received * 3.0 * value_bytes / seconds / 1e6);
    }
    for (auto encoding : {ColumnEncoding::kPacked, ColumnEncoding::kRaw}) {
      auto wire_client = StreamClient(wire_target, precision, batch, encoding);
      uint64_t received = 0;
      const double wire_seconds =
          Best([&] { return StreamSeconds(*wire_client, request, &received); });
      std::printf(
          "| %s, %s: wire path only (no generation), ratio to raw bytes | %.2f (%.1f M samples/s) "
          "|\n",
          name, encoding == ColumnEncoding::kRaw ? "raw columns" : "packed columns",
          raw_seconds / wire_seconds, received / wire_seconds / 1e6);
    }
  }

  if (!only.empty() || args.repeat > 0) {
    server->Shutdown(1);
    unpipelined->Shutdown(1);
    raw_server->Shutdown();
    wire_server->Shutdown();
    return 0;
  }
  {
    // Cold: a fresh server each time, so the tree is built; then the same
    // request again from its cache. The best of three of each.
    const SampleRequest request = Request("eight", "gaussian:floor=0.05", 1'000'000);
    uint64_t received = 0;
    double first = 1e9, hit = 1e9, fixed = 1e9;
    for (int i = 0; i < 3; ++i) {
      auto fresh = *SamplerServer::Start(options);
      ClientOptions co;
      co.target = "127.0.0.1:" + std::to_string(fresh->port());
      auto client = *SamplerClient::Connect(co);
      first = std::min(first, StreamSeconds(*client, request, &received));
      hit = std::min(hit, StreamSeconds(*client, request, &received));
      // A hit that streams one sample: the request's fixed cost (lookup,
      // header, round trip).
      fixed =
          std::min(fixed, StreamSeconds(*client, SamplerClient::Range(request, 0, 1), &received));
      fresh->Shutdown(1);
    }
    std::printf("| first request, 10^6 samples, eight surface, curvature density | %.3f s |\n",
                first);
    std::printf("| the same request again (cache hit) | %.3f s |\n", hit);
    std::printf("| first / hit | %.1fx |\n", first / hit);
    // Where the hit's time goes: generating the same samples in process from
    // a tree built beforehand.
    const double generate =
        std::min(GenerationSeconds(request, options.limits.generation_threads, 65536),
                 GenerationSeconds(request, options.limits.generation_threads, 65536));
    std::printf("| of the hit: generating the 10^6 samples in process, %d threads | %.3f s |\n",
                options.limits.generation_threads, generate);
    std::printf("| of the hit: a hit streaming 1 sample (lookup, header, round trip) | %.4f s |\n",
                fixed);
    // The hit's columns (u v x y z float64) as raw bytes over the same
    // loopback: no server can stream them faster, so first / floor bounds
    // the first / hit ratio of any cache.
    const uint64_t hit_payload = request.count * 5 * 8;
    const double floor = Best([&] { return RawSeconds(raw_target, hit_payload, 65536 * 5 * 8); });
    std::printf("| the hit's %llu MB of columns as raw bytes (a floor for any hit) | %.3f s |\n",
                static_cast<unsigned long long>(hit_payload / 1000000), floor);
    std::printf("| first / that floor: the most any cache could save | %.1fx |\n", first / floor);
  }

  {
    const int clients = 16;
    const uint64_t each = 1'000'000;
    ClientOptions co;
    co.target = target;
    auto warm = *SamplerClient::Connect(co);
    uint64_t received = 0;
    StreamSeconds(*warm, Request("torus", "uniform", each), &received);
    std::vector<std::thread> threads;
    std::vector<uint64_t> got(clients);
    const auto start = Clock::now();
    for (int i = 0; i < clients; ++i) {
      threads.emplace_back([&, i] {
        auto client = *SamplerClient::Connect(co);
        SampleRequest r = Request("torus", "uniform", each);
        r.seed = i;
        StreamSeconds(*client, r, &got[i]);
      });
    }
    for (auto& t : threads) t.join();
    const double seconds = Since(start);
    uint64_t total = 0;
    for (uint64_t g : got) total += g;
    std::printf(
        "| 16 concurrent clients x 10^6 samples (torus, cached) | %.2f M samples/s aggregate |\n",
        total / seconds / 1e6);
  }
  server->Shutdown(1);
  unpipelined->Shutdown(1);
  raw_server->Shutdown();
  wire_server->Shutdown();
  return 0;
}

}  // namespace
}  // namespace sfc

int main(int argc, char** argv) {
  sfc::Args args;
  int positional = 0;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a.rfind("--repeat=", 0) == 0) {
      args.repeat = std::atoi(a.c_str() + 9);
    } else if (a == "--raw") {
      args.raw = true;
    } else if (a == "--glibc-malloc") {
      args.glibc_malloc = true;
    } else if (positional == 0 && !a.empty() && a[0] != '-') {
      args.n = std::strtoull(a.c_str(), nullptr, 10), ++positional;
    } else if (positional == 1 && (a == "float32" || a == "float64")) {
      args.only = a, ++positional;
    } else {
      std::fprintf(stderr,
                   "usage: stream_benchmark [samples] [float32|float64] [--repeat=K [--raw]] "
                   "[--glibc-malloc]\n");
      return 2;
    }
  }
  if (args.repeat > 0 && args.only.empty()) args.only = "float32";
  return sfc::Run(args);
}
