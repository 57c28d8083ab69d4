// sfcsampler-example-client: the smallest program built on the client
// library alone (client/sampler_client.h: gRPC, Protobuf, Abseil, OpenSSL and
// the request library; none of the sampler). Streams a sample set from a
// server and prints its count, its first point and the mean of its points.
//   sfcsampler-example-client --server 127.0.0.1:50051 --surface torus --count 10000
// Exit 0 on success, 1 with the server's error otherwise.
#include <cstdio>
#include <string>

#include "CLI/CLI.hpp"
#include "client/sampler_client.h"

int main(int argc, char** argv) {
  sfc::ClientOptions options;
  sfc::SampleRequest request;
  request.count = 10000;
  CLI::App app{"sfcsampler-example-client: stream samples from a server with the client library"};
  app.add_option("--server", options.target, "host:port of an sfcsampler-server")
      ->capture_default_str();
  app.add_option("--surface", request.tree.surface, "surface spec")->capture_default_str();
  app.add_option("--density", request.tree.density, "density spec")->capture_default_str();
  app.add_option("--count", request.count, "samples in the set")->capture_default_str();
  app.add_option("--seed", request.seed, "seed")->capture_default_str();
  CLI11_PARSE(app, argc, argv);

  auto client = sfc::SamplerClient::Connect(options);
  if (!client.ok()) {
    std::fprintf(stderr, "error: %s\n", client.status().ToString().c_str());
    return 1;
  }
  double sum[3] = {0, 0, 0}, first[3] = {0, 0, 0};
  uint64_t seen = 0;
  auto summary =
      (*client)->Sample(request, [&](const sfc::StreamInfo&, const sfc::SampleBatch& batch) {
        for (size_t i = 0; i < batch.size(); ++i, ++seen) {
          const double p[3] = {batch.x[i], batch.y[i], batch.z[i]};
          for (int c = 0; c < 3; ++c) {
            if (seen == 0) first[c] = p[c];
            sum[c] += p[c];
          }
        }
        return absl::OkStatus();
      });
  if (!summary.ok()) {
    std::fprintf(stderr, "error: %s\n", summary.status().ToString().c_str());
    return 1;
  }
  std::printf("%llu samples of %s (tree %s, %s)\n", static_cast<unsigned long long>(seen),
              request.tree.surface.c_str(), summary->header.tree.key.c_str(),
              summary->header.algorithm_version.c_str());
  std::printf("first (%.17g, %.17g, %.17g)\n", first[0], first[1], first[2]);
  if (seen > 0)
    std::printf("mean (%.6f, %.6f, %.6f)\n", sum[0] / seen, sum[1] / seen, sum[2] / seen);
  return 0;
}
