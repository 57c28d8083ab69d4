// Models over the wire (issue 21): hostile uploads get bounded, escaped
// errors with the right code, names are the sender's own, and the routing
// key of every request about a model is the model's. A real server on a
// loopback port and the real client; every file is made here.
#include <chrono>
#include <string>
#include <thread>
#include <vector>

#include "absl/strings/str_cat.h"
#include "client/sampler_client.h"
#include "engine/model_source.h"
#include "gtest/gtest.h"
#include "proto/convert.h"
#include "server/sampler_server.h"

namespace sfc {
namespace {

namespace v1 = ::sfcsampler::v1;

ServerOptions LoopbackOptions() {
  ServerOptions o;
  o.address = "127.0.0.1:0";
  o.health_address = "";
  o.metrics_address = "";
  return o;
}

struct Running {
  std::unique_ptr<SamplerServer> server;
  std::unique_ptr<SamplerClient> client;
};

Running StartServer(const ServerOptions& options) {
  Running r;
  auto server = SamplerServer::Start(options);
  EXPECT_TRUE(server.ok()) << server.status();
  r.server = *std::move(server);
  ClientOptions client;
  client.target = "127.0.0.1:" + std::to_string(r.server->port());
  r.client = *SamplerClient::Connect(client);
  return r;
}

SampleRequest Request(const std::string& surface, uint64_t count) {
  SampleRequest r;
  r.tree.surface = surface;
  r.count = count;
  r.seed = 1;
  return r;
}

absl::Status SampleStatus(SamplerClient& client, const SampleRequest& request) {
  auto s = client.Sample(request, [](const v1::StreamHeader&, const SampleBatch&) {
    return absl::OkStatus();
  });
  return s.status();
}

constexpr char kSquareObj[] = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\n";

// A 100 000-digit index: the real INVALID_ARGUMENT arrives (not the
// client's RESOURCE_EXHAUSTED about header size), under 1 KB, the token
// clipped.
TEST(ServerModels, AGiantTokenGivesABoundedInvalidArgument) {
  Running r = StartServer(LoopbackOptions());
  const std::string obj = absl::StrCat(kSquareObj, "f 1 2 ", std::string(100000, '9'), "\n");
  auto info = r.client->UploadModel("obj", "giant.obj", obj);
  ASSERT_TRUE(info.ok()) << info.status();
  const absl::Status s = SampleStatus(*r.client, Request(info->spec(), 100));
  EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument) << s;
  EXPECT_LE(s.message().size(), kMaxStatusMessageBytes);
  EXPECT_NE(s.message().find("(100000 bytes)"), std::string::npos) << s.message();
  // The server still serves.
  EXPECT_TRUE(SampleStatus(*r.client, Request("sphere", 100)).ok());
}

// Any status, however long, leaves the server clipped to 1 KB.
TEST(ServerModels, ToGrpcStatusClipsMessages) {
  const grpc::Status s = ToGrpcStatus(absl::InvalidArgumentError(std::string(1 << 20, 'x')));
  EXPECT_EQ(s.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_LE(s.error_message().size(), kMaxStatusMessageBytes);
  EXPECT_NE(s.error_message().find("clipped"), std::string::npos);
  EXPECT_EQ(ToGrpcStatus(absl::NotFoundError("short")).error_message(), "short");
}

// A newline and a megabyte in the upload name forge no log line and make
// no long message; a second client sending the same bytes under another
// name never sees the first one's name.
TEST(ServerModels, UploadNamesAreEscapedCappedAndNeverShownToAnotherClient) {
  ServerOptions options = LoopbackOptions();
  options.max_model_bytes = 1 << 10;
  Running r = StartServer(options);
  const std::string forged = absl::StrCat("part.step\nrpc=Forged", std::string(1 << 20, 'n'));
  const absl::Status big =
      r.client->UploadModel("obj", forged, std::string(2 << 10, 'x')).status();
  EXPECT_EQ(big.code(), absl::StatusCode::kResourceExhausted) << big;
  EXPECT_EQ(big.message().find('\n'), std::string::npos) << big.message();
  EXPECT_NE(big.message().find("part.step\\nrpc=Forged"), std::string::npos) << big.message();
  EXPECT_LE(big.message().size(), kMaxStatusMessageBytes);

  const std::string bad = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n";
  auto first = r.client->UploadModel("obj", "secret_part_name.obj", bad);
  ASSERT_TRUE(first.ok()) << first.status();
  auto second = r.client->UploadModel("obj", "mine.obj", bad);
  ASSERT_TRUE(second.ok()) << second.status();
  EXPECT_TRUE(second->already_stored());
  const absl::Status s = SampleStatus(*r.client, Request(second->spec(), 100));
  EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument) << s;
  EXPECT_EQ(s.message().find("secret_part_name"), std::string::npos) << s.message();
  EXPECT_NE(s.message().find(second->spec()), std::string::npos) << s.message();
}

// Behind a consistent-hash proxy, FindModel, UploadModel and the Sample of
// one model must carry one key: the model's, whatever the density.
TEST(ServerModels, EveryRequestAboutAModelCarriesTheModelsRoutingKey) {
  const std::string sha = Sha256Hex(kSquareObj);
  const std::string key = ModelRoutingKey(ModelFormat::kObj, sha);
  EXPECT_EQ(key, "obj:sha256=" + sha);
  TreeSpec spec;
  spec.surface = "obj:sha256=" + sha;
  EXPECT_EQ(SamplerClient::SurfaceKey(spec), key);
  spec.density = "expr:1+x*x";
  EXPECT_EQ(SamplerClient::SurfaceKey(spec), key);
  spec.surface = "sphere";
  EXPECT_NE(SamplerClient::SurfaceKey(spec), key);
}

}  // namespace
}  // namespace sfc
