// Service benchmarks; prints a Markdown table. Everything runs in this
// process over loopback TCP: a real sfcsampler server, the C++ client
// library, and a raw-bytes gRPC stream as the baseline measured in the same
// run.
//   stream_benchmark [samples]   (default 10^7)
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>
#include <vector>

#include "bench/raw_stream.grpc.pb.h"
#include "client/sampler_client.h"
#include "grpcpp/create_channel.h"
#include "grpcpp/server_builder.h"
#include "server/sampler_server.h"

namespace sfc {
namespace {

namespace v1 = ::sfcsampler::v1;
using Clock = std::chrono::steady_clock;

double Since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

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

// Streams a request, touching every sample; returns seconds and bytes of payload.
double StreamSeconds(SamplerClient& client, const SampleRequest& request, uint64_t* received) {
  const auto start = Clock::now();
  double sink = 0;
  auto s = client.Sample(request, [&](const v1::StreamHeader&, const SampleBatch& b) {
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

int Run(uint64_t n) {
  ServerOptions options;
  options.address = "127.0.0.1:0";
  options.health_address = "";
  options.metrics_address = "";
  options.limits.max_tree_leaves = uint64_t{1} << 26;
  auto server = *SamplerServer::Start(options);
  const std::string target = "127.0.0.1:" + std::to_string(server->port());

  RawStreamService raw;
  grpc::ServerBuilder builder;
  int raw_port = 0;
  builder.AddListeningPort("127.0.0.1:0", grpc::InsecureServerCredentials(), &raw_port);
  builder.RegisterService(&raw);
  auto raw_server = builder.BuildAndStart();
  const std::string raw_target = "127.0.0.1:" + std::to_string(raw_port);

  std::printf("| measurement | value |\n|---|---:|\n");
  const uint32_t batch = 65536;
  for (auto precision : {v1::PRECISION_FLOAT32, v1::PRECISION_FLOAT64}) {
    ClientOptions co;
    co.target = target;
    co.precision = precision;
    co.batch_size = batch;
    auto client = *SamplerClient::Connect(co);
    const SampleRequest request = Request("sphere", "uniform", n);
    uint64_t received = 0;
    StreamSeconds(*client, request, &received);  // warm: build and cache the tree
    const double seconds = StreamSeconds(*client, request, &received);
    const size_t value_bytes = precision == v1::PRECISION_FLOAT32 ? 4 : 8;
    const uint64_t payload = received * 5 * value_bytes;
    const double raw_seconds = RawSeconds(raw_target, payload, static_cast<uint32_t>(batch * 5 * value_bytes));
    const char* name = precision == v1::PRECISION_FLOAT32 ? "float32" : "float64";
    std::printf("| %s: %llu samples streamed (sphere, cached tree) | %.2f M samples/s (%.0f MB/s) |\n", name,
                static_cast<unsigned long long>(received), received / seconds / 1e6, payload / seconds / 1e6);
    std::printf("| %s: raw bytes stream of the same %llu MB | %.0f MB/s |\n", name,
                static_cast<unsigned long long>(payload / 1000000), payload / raw_seconds / 1e6);
    std::printf("| %s: ratio samples / raw | %.2f |\n", name, raw_seconds / seconds);
  }

  {
    ClientOptions co;
    co.target = target;
    auto client = *SamplerClient::Connect(co);
    const SampleRequest request = Request("eight", "gaussian:floor=0.05", 1'000'000);
    uint64_t received = 0;
    const double first = StreamSeconds(*client, request, &received);
    const double hit = StreamSeconds(*client, request, &received);
    std::printf("| first request, 10^6 samples, eight surface, curvature density | %.3f s |\n", first);
    std::printf("| the same request again (cache hit) | %.3f s |\n", hit);
    std::printf("| first / hit | %.1fx |\n", first / hit);
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
    std::printf("| 16 concurrent clients x 10^6 samples (torus, cached) | %.2f M samples/s aggregate |\n",
                total / seconds / 1e6);
  }
  server->Shutdown(1);
  raw_server->Shutdown();
  return 0;
}

}  // namespace
}  // namespace sfc

int main(int argc, char** argv) {
  return sfc::Run(argc > 1 ? std::strtoull(argv[1], nullptr, 10) : 10'000'000);
}
