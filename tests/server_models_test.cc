// Models over the wire (issue 21): hostile uploads get bounded, escaped
// errors with the right code, names are the sender's own, and the routing
// key of every request about a model is the model's. A real server on a
// loopback port and the real client; every file is made here.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <functional>
#include <memory>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "cad/fixtures.h"
#include "client/sampler_client.h"
#include "engine/model_source.h"
#include "grpcpp/create_channel.h"
#include "gtest/gtest.h"
#include "mesh/mesh_loader.h"
#include "proto/convert.h"
#include "request/model_spec.h"
#include "request/routing_key.h"
#include "server/sampler_server.h"
#include "tests/server_test_util.h"

namespace sfc {
namespace {

namespace v1 = ::sfcsampler::v1;

using testing::ConnectWithDeadline;
using testing::LoopbackOptions;
using testing::Request;
using testing::Running;
using testing::StartServer;

absl::Status SampleStatus(SamplerClient& client, const SampleRequest& request) {
  auto s = client.Sample(request,
                         [](const StreamInfo&, const SampleBatch&) { return absl::OkStatus(); });
  return s.status();
}

// A server as sfcsampler-server runs one: CAD files are read by the
// model check program, in a process of its own.
ServerOptions ModelServerOptions() {
  ServerOptions options = LoopbackOptions();
  options.limits.model_check_program = SFC_MODEL_CHECK_PROGRAM;
  return options;
}

// A stub of the server's own service, for streams the client library would
// not send (idle, trickling).
std::unique_ptr<v1::Sampler::Stub> RawStub(const Running& r) {
  return v1::Sampler::NewStub(grpc::CreateChannel(
      "127.0.0.1:" + std::to_string(r.server->port()), grpc::InsecureChannelCredentials()));
}

// The bytes uploads hold once cut uploads' handlers have returned (they give
// the bytes back as they return, just after the cut): waits up to 2 s for 0.
uint64_t UploadBytesOnceFreed(const Running& r) {
  const auto freed_by = std::chrono::steady_clock::now() + std::chrono::seconds(2);
  while (r.server->models().stats().upload_bytes != 0 &&
         std::chrono::steady_clock::now() < freed_by) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return r.server->models().stats().upload_bytes;
}

constexpr char kSquareObj[] = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\n";

// An upload that declared its size holds that size from its first chunk;
// one that has sent nothing holds nothing. Idle uploads keep what they hold
// only until the idle cut: while four hold the budget another client is told
// to retry, and after they are cut (the client sees CANCELLED, the server's
// log says why) its upload goes through and no partial model is stored.
TEST(ServerModels, IdleUploadsHoldTheirDeclaredSizeOnlyUntilCut) {
  ServerOptions options = LoopbackOptions();
  options.max_model_bytes = 1000;
  options.model_bytes = 4 * 1000 + 40;  // the 48-byte square does not fit beside them
  options.upload_idle_timeout_seconds = 3;
  Running r = StartServer(options);
  auto stub = RawStub(r);
  struct Idle {
    grpc::ClientContext context;
    v1::ModelInfo info;
    std::unique_ptr<grpc::ClientWriter<v1::ModelChunk>> writer;
  };
  std::vector<std::unique_ptr<Idle>> idle;
  for (int i = 0; i < 5; ++i) {
    idle.push_back(std::make_unique<Idle>());
    Idle& u = *idle.back();
    // Bounds the test should the server never cut them.
    u.context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(30));
    u.writer = stub->UploadModel(&u.context, &u.info);
    if (i == 4) break;  // the fifth sends nothing at all
    v1::ModelChunk chunk;
    chunk.set_format("obj");
    chunk.set_total_bytes(1000);
    chunk.set_data("v 0 0 0\n");
    ASSERT_TRUE(u.writer->Write(chunk)) << i;
  }
  // Every idle upload's first chunk has arrived.
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  while (r.server->models().stats().upload_bytes < 4 * 1000 &&
         std::chrono::steady_clock::now() < until) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  EXPECT_EQ(r.server->models().stats().upload_bytes, 4u * 1000);
  auto refused = r.client->UploadModel("obj", "square.obj", kSquareObj);
  EXPECT_EQ(refused.status().code(), absl::StatusCode::kResourceExhausted) << refused.status();
  EXPECT_NE(std::string(refused.status().message()).find("retry"), std::string::npos)
      << refused.status();
  // Then the idle ones are cut, well before a generous bound.
  const auto start = std::chrono::steady_clock::now();
  for (auto& u : idle) {
    const grpc::Status status = u->writer->Finish();
    EXPECT_EQ(status.error_code(), grpc::StatusCode::CANCELLED) << status.error_message();
  }
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(15));
  EXPECT_EQ(UploadBytesOnceFreed(r), 0u);
  EXPECT_EQ(r.server->models().stats().models, 0u);  // no partial model was stored
  auto info = r.client->UploadModel("obj", "square.obj", kSquareObj);
  ASSERT_TRUE(info.ok()) << info.status();
  EXPECT_EQ(r.server->models().stats().models, 1u);
}

// A client that sends a few bytes just before every idle cut keeps its
// declared size only until it falls below the minimum rate: it gets
// DEADLINE_EXCEEDED saying so, and the budget it held comes back. A client
// that sends at the rate is not cut.
TEST(ServerModels, ATricklingUploadIsCutAtTheMinimumRate) {
  ServerOptions options = LoopbackOptions();
  options.max_model_bytes = 100000;
  options.upload_idle_timeout_seconds = 0.6;
  options.upload_min_bytes_per_second = 2000;
  Running r = StartServer(options);
  auto stub = RawStub(r);
  const auto upload = [&](size_t size, int bytes_a_chunk) {
    grpc::ClientContext context;
    // Bounds the test should the server never cut it.
    context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(30));
    v1::ModelInfo info;
    auto writer = stub->UploadModel(&context, &info);
    const std::string obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    std::string rest = obj + std::string(size - obj.size(), '\n');  // a valid OBJ
    v1::ModelChunk chunk;
    chunk.set_format("obj");
    chunk.set_total_bytes(rest.size());
    // A chunk every 0.25 s: each gap well inside the idle timeout.
    for (bool first = true; !rest.empty(); first = false) {
      if (!first) std::this_thread::sleep_for(std::chrono::milliseconds(250));
      const size_t n = std::min<size_t>(bytes_a_chunk, rest.size());
      chunk.set_data(rest.substr(0, n));
      rest.erase(0, n);
      if (!writer->Write(chunk)) break;
      chunk.clear_format();
      chunk.clear_total_bytes();
    }
    writer->WritesDone();
    return writer->Finish();
  };
  // 8 bytes every 0.25 s: 32 bytes a second.
  const auto start = std::chrono::steady_clock::now();
  const grpc::Status slow = upload(6000, 8);
  EXPECT_EQ(slow.error_code(), grpc::StatusCode::DEADLINE_EXCEEDED) << slow.error_message();
  EXPECT_NE(slow.error_message().find("upload_min_rate"), std::string::npos)
      << slow.error_message();
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(5));
  EXPECT_EQ(UploadBytesOnceFreed(r), 0u);
  EXPECT_EQ(r.server->models().stats().models, 0u);
  // 1 000 bytes every 0.25 s, twice the minimum rate, for twice the idle
  // timeout: stored.
  const grpc::Status fast = upload(6000, 1000);
  EXPECT_TRUE(fast.ok()) << fast.error_message();
  EXPECT_EQ(r.server->models().stats().models, 1u);
}

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

// A model given as bytes travels once: the first EnsureModelBytes uploads it,
// the second finds it by its hash; both name it by that hash.
TEST(ServerModels, ModelBytesAreUploadedOnlyWhenTheServerLacksThem) {
  Running r = StartServer(LoopbackOptions());
  const std::string spec = "obj:sha256=" + Sha256Hex(kSquareObj);
  auto first = r.client->EnsureModelBytes(ModelFormat::kObj, "square.obj", kSquareObj);
  ASSERT_TRUE(first.ok()) << first.status();
  EXPECT_EQ(*first, spec);
  EXPECT_EQ(r.server->models().stats().uploads, 1u);
  auto again = r.client->EnsureModelBytes(ModelFormat::kObj, "other name.obj", kSquareObj);
  ASSERT_TRUE(again.ok()) << again.status();
  EXPECT_EQ(*again, spec);
  EXPECT_EQ(r.server->models().stats().uploads, 1u);
  EXPECT_TRUE(SampleStatus(*r.client, Request(spec, 100)).ok());
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
  EXPECT_EQ(RoutingKey(spec), key);
  spec.density = "expr:1+x*x";
  EXPECT_EQ(RoutingKey(spec), key);
  spec.surface = "sphere";
  EXPECT_NE(RoutingKey(spec), key);
}


// A sphere whose shell lists its one face `copies` times: small, valid, and
// quadratic in OpenCASCADE's shell healing (20 000 copies: 2.3 s of CPU).
std::string HostileShellStep(int copies) {
  auto step = cad::fixtures::SolidBytes(cad::fixtures::Solid::kSphere, ModelFormat::kStep);
  EXPECT_TRUE(step.ok()) << step.status();
  std::string text = *step;
  const size_t shell = text.find("CLOSED_SHELL('',(");
  const size_t open = text.find('(', text.find(',', shell));
  const size_t close = text.find(')', open);
  const std::string face = text.substr(open + 1, close - open - 1);
  text.replace(open + 1, close - open - 1,
               absl::StrJoin(std::vector<std::string>(copies, face), ","));
  return text;
}

double Seconds(const std::function<void()>& f) {
  const auto start = std::chrono::steady_clock::now();
  f();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// The parse's CPU budget stops it, the failure is remembered per content
// hash, and no stream slot is held meanwhile: in process (OpenCASCADE's user
// break), and in the model check process, as a server runs, where nothing
// asks the kernel to stop and only the process's RLIMIT_CPU ends the parse,
// as it ends a loop that never polls the user break.
TEST(ServerModels, AHostileParseIsStoppedAtItsBudgetAndRemembered) {
  for (const bool in_check_process : {false, true}) {
    SCOPED_TRACE(in_check_process ? "in the model check process" : "in process");
    ServerOptions options = in_check_process ? ModelServerOptions() : LoopbackOptions();
    options.limits.model_parse_seconds = 0.5;
    Running r = StartServer(options);
    auto info = r.client->UploadModel("step", "shell.step", HostileShellStep(60000));
    ASSERT_TRUE(info.ok()) << info.status();
    absl::Status first;
    const double cpu0 = static_cast<double>(std::clock()) / CLOCKS_PER_SEC;
    const double t1 =
        Seconds([&] { first = SampleStatus(*r.client, Request(info->spec(), 1000)); });
    const double cpu = static_cast<double>(std::clock()) / CLOCKS_PER_SEC - cpu0;
    EXPECT_EQ(first.code(), absl::StatusCode::kResourceExhausted) << first;
    EXPECT_NE(first.message().find("model_parse_seconds"), std::string::npos) << first;
    std::printf("hostile parse refused after %.2f s (%.2f s of this process's CPU)\n", t1, cpu);
    EXPECT_LT(t1, 10.0) << "the budget of 0.5 s CPU did not stop the parse";
    absl::Status again;
    const double t2 =
        Seconds([&] { again = SampleStatus(*r.client, Request(info->spec(), 1000)); });
    EXPECT_EQ(again.code(), absl::StatusCode::kResourceExhausted) << again;
    EXPECT_LT(t2, 0.5) << "the failed parse was not remembered";
    auto stats = r.client->GetCacheStats();
    ASSERT_TRUE(stats.ok());
    EXPECT_EQ(stats->model_parses(), 1u);
    EXPECT_EQ(stats->model_parse_failures(), 1u);
    EXPECT_EQ(stats->model_parse_seconds(), 0.5);
  }
}

// 4 hostile uploads parsing (one parse thread, 2 stream slots): another
// client's request completes within 2x its usual time (plus 50 ms of
// scheduling slack on a shared machine), and is not refused for slots.
TEST(ServerModels, AGoodRequestWhileFourHostileUploadsParseTakesAtMostTwiceItsTime) {
  ServerOptions options = LoopbackOptions();
  options.limits.model_parse_seconds = 30;
  options.limits.model_parse_threads = 1;
  options.limits.generation_threads = 1;
  options.max_concurrent_streams = 2;
  Running r = StartServer(options);
  const SampleRequest good = Request("torus", 200000);
  ASSERT_TRUE(SampleStatus(*r.client, good).ok());  // its tree is cached from here on
  auto median_seconds = [&] {
    std::vector<double> t;
    for (int i = 0; i < 5; ++i) {
      t.push_back(Seconds([&] { EXPECT_TRUE(SampleStatus(*r.client, good).ok()); }));
    }
    std::sort(t.begin(), t.end());
    return t[2];
  };
  const double usual = median_seconds();
  std::vector<std::string> specs;
  for (int i = 0; i < 4; ++i) {
    auto info = r.client->UploadModel("step", absl::StrCat("hostile", i, ".step"),
                                      HostileShellStep(40000 + i));
    ASSERT_TRUE(info.ok()) << info.status();
    specs.push_back(info->spec());
  }
  std::vector<std::thread> hostile;
  std::vector<std::unique_ptr<SamplerClient>> clients;
  for (const std::string& spec : specs) {
    clients.push_back(ConnectWithDeadline(*r.server, 20));
    hostile.emplace_back([client = clients.back().get(), spec] {
      SampleStatus(*client, Request(spec, 1000)).IgnoreError();
    });
  }
  // Until the parses run (one) and wait (three).
  for (int i = 0; i < 200; ++i) {
    auto s = r.client->GetCacheStats();
    if (s.ok() && s->model_parses_running() == 1 && s->model_parses_queued() == 3) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  auto during = r.client->GetCacheStats();
  ASSERT_TRUE(during.ok());
  EXPECT_EQ(during->model_parses_running(), 1u);
  const double busy = median_seconds();
  auto after = r.client->GetCacheStats();
  ASSERT_TRUE(after.ok());
  EXPECT_EQ(after->model_parses_running(), 1u) << "the hostile parses ended before the measurement";
  std::printf("good request: usual %.3f s, with 4 hostile parses %.3f s (%.2fx)\n", usual, busy,
              busy / usual);
  EXPECT_LE(busy, 2 * usual + 0.05);
  r.server->Shutdown(0, 0);  // stops the parses; the hostile clients get their errors
  for (std::thread& t : hostile) t.join();
}

// Issue 37: CAD against CAD. A server as it runs (model check process, two
// parse slots, each held for its first 0.2 s): while two and while four
// hostile STEPs parse in the check process, a cold 2 KB STEP sphere (fresh
// bytes each time, so each request parses) is served long before the
// hostile clients leave (4 s), where one parse thread held to the end made
// it wait for them. The 2x target is bench/parse_isolation.py's, on a quiet
// machine: here other tests share the two cores.
TEST(ServerModels, ASmallStepIsServedWhileHostileStepsParse) {
  ServerOptions options = ModelServerOptions();
  options.limits.model_parse_threads = 2;
  options.limits.model_parse_fresh_seconds = 0.2;
  options.limits.max_long_parses = 4;
  options.limits.model_parse_seconds = 30;
  Running r = StartServer(options);
  auto sphere = cad::fixtures::SolidBytes(cad::fixtures::Solid::kSphere, ModelFormat::kStep);
  ASSERT_TRUE(sphere.ok()) << sphere.status();
  int serial = 0;
  auto cold_sphere = [&] {
    std::string bytes = *sphere;
    bytes.replace(bytes.find("FILE_NAME('"), 11, absl::StrCat("FILE_NAME('cold", ++serial));
    return Seconds([&] {
      auto info = r.client->UploadModel("step", "sphere.step", bytes);
      ASSERT_TRUE(info.ok()) << info.status();
      EXPECT_TRUE(SampleStatus(*r.client, Request(info->spec(), 1000)).ok());
    });
  };
  auto median_of_3 = [&] {
    std::vector<double> t = {cold_sphere(), cold_sphere(), cold_sphere()};
    std::sort(t.begin(), t.end());
    return t[1];
  };
  cold_sphere();  // the CAD module loaded
  const double usual = median_of_3();
  for (const int hostile_count : {2, 4}) {
    SCOPED_TRACE(absl::StrCat(hostile_count, " hostile parses"));
    std::vector<std::thread> hostile;
    std::vector<std::unique_ptr<SamplerClient>> clients;
    for (int i = 0; i < hostile_count; ++i) {
      auto info = r.client->UploadModel("step", "hostile.step",
                                        HostileShellStep(40000 + 10 * hostile_count + i));
      ASSERT_TRUE(info.ok()) << info.status();
      // Stays connected 4 s, then leaves: its parse stops.
      clients.push_back(ConnectWithDeadline(*r.server, 4));
      hostile.emplace_back([client = clients.back().get(), spec = info->spec()] {
        SampleStatus(*client, Request(spec, 1000)).IgnoreError();
      });
    }
    for (int i = 0; i < 300; ++i) {  // until every hostile parse is past its slot
      auto s = r.client->GetCacheStats();
      if (s.ok() && s->model_parses_long() == static_cast<uint64_t>(hostile_count)) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    const double busy = median_of_3();
    auto during = r.client->GetCacheStats();
    ASSERT_TRUE(during.ok());
    // Still running (a slowed small parse may have taken one's place among
    // the long parses: engine/loaded_models.h).
    EXPECT_GE(during->model_parses_long(), static_cast<uint64_t>(hostile_count) - 1)
        << "the hostile parses ended before the measurement";
    std::printf("cold 2 KB STEP: usual %.3f s, with %d hostile parses %.3f s (%.2fx)\n", usual,
                hostile_count, busy, busy / usual);
    EXPECT_LT(busy, 2.0) << "the small model waited for the hostile parses (4 s)";
    for (std::thread& t : hostile) t.join();
    for (int i = 0; i < 300 && r.client->GetCacheStats()->model_parses_running() > 0; ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  }
}

// A grid of n x n quads as OBJ (distinct n: distinct bytes).
std::string GridObj(int n) {
  std::string obj;
  for (int i = 0; i <= n; ++i) {
    for (int j = 0; j <= n; ++j) absl::StrAppend(&obj, "v ", i, " ", j, " 0\n");
  }
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      const int a = i * (n + 1) + j + 1;
      absl::StrAppend(&obj, "f ", a, " ", a + n + 1, " ", a + n + 2, " ", a + 1, "\n");
    }
  }
  return obj;
}

// Parsed models are counted in bytes and reported; the parse of a request
// whose tree failed, and the parses of an evicted upload, are dropped.
TEST(ServerModels, ParsedModelsAreCountedAndDroppedWithFailedRequestsAndEvictedUploads) {
  ServerOptions options = LoopbackOptions();
  const std::string a = GridObj(40), b = GridObj(41);
  options.model_bytes = a.size() + b.size() / 2;  // room for one of them
  options.limits.parsed_model_bytes = 32 << 20;
  Running r = StartServer(options);
  auto info_a = r.client->UploadModel("obj", "a.obj", a);
  ASSERT_TRUE(info_a.ok()) << info_a.status();
  ASSERT_TRUE(SampleStatus(*r.client, Request(info_a->spec(), 1000)).ok());
  auto stats = *r.client->GetCacheStats();
  EXPECT_EQ(stats.parsed_models(), 1u);
  // 41 x 41 vertices, 3200 triangles: positions, triangles, face normals at least.
  EXPECT_GE(stats.parsed_model_bytes(), 41u * 41 * 24 + 3200 * (12 + 24));
  EXPECT_EQ(stats.parsed_model_budget_bytes(), 32u << 20);
  // A density that is zero everywhere: the tree fails, the parse is not kept.
  SampleRequest zero = Request(info_a->spec(), 1000);
  zero.tree.density = "expr:0*x";
  EXPECT_EQ(SampleStatus(*r.client, zero).code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(r.client->GetCacheStats()->parsed_models(), 0u);
  ASSERT_TRUE(SampleStatus(*r.client, Request(info_a->spec(), 1000)).ok());
  EXPECT_EQ(r.client->GetCacheStats()->parsed_models(), 1u);
  // Uploading b evicts a from the store, and a's parse goes with it.
  auto info_b = r.client->UploadModel("obj", "b.obj", b);
  ASSERT_TRUE(info_b.ok()) << info_b.status();
  stats = *r.client->GetCacheStats();
  EXPECT_EQ(stats.models(), 1u);
  EXPECT_EQ(stats.model_evictions(), 1u);
  EXPECT_EQ(stats.parsed_models(), 0u);
  EXPECT_EQ(stats.parsed_model_bytes(), 0u);
}

// Parses' working memory follows --parse-memory-bytes: a model whose parse
// would need more (estimated from its size before parsing) is refused with
// RESOURCE_EXHAUSTED naming the flag, and a model that fits samples; an
// upload's bytes are counted as they arrive and none stay held after it.
TEST(ServerModels, ParseMemoryAndUploadsInFlightFollowTheirBudgets) {
  ServerOptions options = LoopbackOptions();
  const std::string small = GridObj(10), large = GridObj(200);
  // Room for the small grid's parse, not the large one's.
  const uint64_t small_parse = MeshParseMemoryBytes(ModelFormat::kObj, small);
  const uint64_t large_parse = MeshParseMemoryBytes(ModelFormat::kObj, large);
  options.limits.parse_memory_bytes = (small_parse + large_parse) / 2;
  ASSERT_GT(large_parse, options.limits.parse_memory_bytes);
  ASSERT_LT(small_parse, options.limits.parse_memory_bytes);
  Running r = StartServer(options);
  auto info_small = r.client->UploadModel("obj", "small.obj", small);
  ASSERT_TRUE(info_small.ok()) << info_small.status();
  EXPECT_TRUE(SampleStatus(*r.client, Request(info_small->spec(), 1000)).ok());
  auto info_large = r.client->UploadModel("obj", "large.obj", large);
  ASSERT_TRUE(info_large.ok()) << info_large.status();
  const absl::Status refused = SampleStatus(*r.client, Request(info_large->spec(), 1000));
  EXPECT_EQ(refused.code(), absl::StatusCode::kResourceExhausted);
  EXPECT_NE(refused.message().find("parse_memory_bytes"), std::string::npos) << refused;
  const auto stats = *r.client->GetCacheStats();
  EXPECT_EQ(stats.parse_memory_bytes(), options.limits.parse_memory_bytes);
  EXPECT_EQ(stats.parse_memory_reserved(), 0u);
  EXPECT_EQ(stats.model_upload_bytes(), 0u);
  EXPECT_EQ(stats.model_bytes(), small.size() + large.size());
}

// A cached mesh tree keeps its mesh alive after the parse is dropped (its
// upload evicted): the tree cache counts the mesh with the tree, so its
// budget bounds what trees pin (the soak's model phase found RSS past the
// budgets when it did not).
TEST(ServerModels, ACachedMeshTreeCountsTheMeshItKeepsAlive) {
  ServerOptions options = LoopbackOptions();
  const std::string a = GridObj(60), b = GridObj(61);
  options.model_bytes = a.size() + b.size() / 2;  // room for one of them
  Running r = StartServer(options);
  auto info_a = r.client->UploadModel("obj", "a.obj", a);
  ASSERT_TRUE(info_a.ok()) << info_a.status();
  ASSERT_TRUE(SampleStatus(*r.client, Request(info_a->spec(), 1000)).ok());
  auto stats = *r.client->GetCacheStats();
  ASSERT_EQ(stats.parsed_models(), 1u);
  const uint64_t mesh_bytes = stats.parsed_model_bytes();
  EXPECT_GE(stats.bytes(), mesh_bytes);
  ASSERT_TRUE(r.client->UploadModel("obj", "b.obj", b).ok());
  stats = *r.client->GetCacheStats();
  EXPECT_EQ(stats.parsed_models(),
            0u);  // a's parse dropped; its tree, cached, still holds the mesh
  EXPECT_GE(stats.bytes(), mesh_bytes);
}

// A model's tree is made before the stream takes a slot, where the stream
// then finds it cached: the header still reports what this request did
// (built, a hit, refined or made for more samples), as for a formula surface.
TEST(ServerModels, TheHeaderReportsAModelsTreeAsTheRequestFoundIt) {
  Running r = StartServer(LoopbackOptions());
  auto info = r.client->UploadModel("obj", "grid.obj", GridObj(20));
  ASSERT_TRUE(info.ok()) << info.status();
  const auto header_tree = [&](uint64_t count) {
    auto s =
        r.client->Sample(Request(info->spec(), count),
                         [](const StreamInfo&, const SampleBatch&) { return absl::OkStatus(); });
    EXPECT_TRUE(s.ok()) << s.status();
    return s.ok() ? s->header.tree : TreeSummary{};
  };
  const TreeSummary first = header_tree(1000);
  EXPECT_FALSE(first.cache_hit);
  EXPECT_FALSE(first.refined);
  const TreeSummary again = header_tree(1000);
  EXPECT_TRUE(again.cache_hit);
  EXPECT_FALSE(again.refined);
  // More samples than the cached tree's grade: a tree made for them.
  const TreeSummary larger = header_tree(1000000);
  EXPECT_FALSE(larger.cache_hit);
  EXPECT_GT(larger.grade, first.grade);  // model trees are made anew, not refined
  EXPECT_FALSE(larger.refined);
}

// A model request the stream could never serve (a batch_size over the
// server's limit, or a set whose working memory exceeds all the stream
// memory) is refused before its model's tree is built, as a formula's is.
TEST(ServerModels, AStreamThatCannotRunIsRefusedBeforeTheModelsTree) {
  ServerOptions options = LoopbackOptions();
  options.stream_memory_bytes = 1 << 20;
  ClientOptions co;
  co.stream.batch_size = options.max_batch_size + 1;
  Running r = StartServer(options, co);
  auto info = r.client->UploadModel("obj", "grid.obj", GridObj(20));
  ASSERT_TRUE(info.ok()) << info.status();
  const absl::Status batch = SampleStatus(*r.client, Request(info->spec(), 1000));
  EXPECT_EQ(batch.code(), absl::StatusCode::kInvalidArgument) << batch;
  EXPECT_NE(batch.message().find("max_batch_size"), std::string::npos) << batch;

  Running small = StartServer(options);
  auto held = small.client->UploadModel("obj", "grid.obj", GridObj(20));
  ASSERT_TRUE(held.ok()) << held.status();
  SampleRequest blue = Request(held->spec(), 50'000);
  blue.sequence = SequenceKind::kBlue;
  blue.begin = 0, blue.end = 10;
  const absl::Status memory = SampleStatus(*small.client, blue);
  EXPECT_EQ(memory.code(), absl::StatusCode::kResourceExhausted) << memory;
  EXPECT_NE(memory.message().find("fewer samples (count)"), std::string::npos) << memory;
  EXPECT_EQ(r.client->GetCacheStats()->builds(), 0u);
  EXPECT_EQ(small.client->GetCacheStats()->builds(), 0u);
}

// The same for a CAD model: its cached tree counts the model it keeps alive.
TEST(ServerModels, ACachedCadTreeCountsTheModelItKeepsAlive) {
  auto step = cad::fixtures::SolidBytes(cad::fixtures::Solid::kSphere, ModelFormat::kStep);
  ASSERT_TRUE(step.ok()) << step.status();
  Running r = StartServer(LoopbackOptions());
  auto info = r.client->UploadModel("step", "sphere.step", *step);
  ASSERT_TRUE(info.ok()) << info.status();
  ASSERT_TRUE(SampleStatus(*r.client, Request(info->spec(), 1000)).ok());
  const auto stats = *r.client->GetCacheStats();
  ASSERT_EQ(stats.parsed_models(), 1u);
  ASSERT_GT(stats.parsed_model_bytes(), 0u);
  EXPECT_GE(stats.bytes(), stats.parsed_model_bytes());
}

// An IGES file whose circular arc has a garbled coordinate ("0&"), found by
// iges_fuzzer: OpenCASCADE 7.6's shape healing spins on it in
// Geom2d_TrimmedCurve::SetTrim without ever polling the user break, so read
// in process it held a parse thread for good. The preflight now refuses it
// at once (cad/preflight.h; a loop it misses would end at the model check
// process's CPU limit, above), and the next model parses on the same
// (single) parse thread.
TEST(ServerModels, AFileThatLoopedTheKernelIsRefusedAndTheNextModelParses) {
  auto iges = cad::fixtures::SolidBytes(cad::fixtures::Solid::kBoxWithHole, ModelFormat::kIges);
  ASSERT_TRUE(iges.ok()) << iges.status();
  const std::string arc = "100,0.,0.,0.,5.,0.,5.,0.;";
  const size_t at = iges->find(arc);
  ASSERT_NE(at, std::string::npos) << "the fixture's arc moved";
  std::string looping = *iges;
  looping.replace(at, arc.size(), "100,0.,0.,0.,5.,0&,5.,0.;");
  ServerOptions options = ModelServerOptions();
  options.limits.model_parse_seconds = 1;
  options.limits.model_parse_threads = 1;
  Running r = StartServer(options);
  auto hostile = r.client->UploadModel("iges", "loop.iges", looping);
  ASSERT_TRUE(hostile.ok()) << hostile.status();
  const auto start = std::chrono::steady_clock::now();
  const absl::Status refused = SampleStatus(*r.client, Request(hostile->spec(), 1000));
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_EQ(refused.code(), absl::StatusCode::kInvalidArgument) << refused;
  EXPECT_NE(refused.message().find("'0&' is not a number"), std::string::npos) << refused;
  EXPECT_LT(seconds, 5.0);
  auto good = r.client->UploadModel("iges", "box.iges", *iges);
  ASSERT_TRUE(good.ok()) << good.status();
  EXPECT_TRUE(SampleStatus(*r.client, Request(good->spec(), 1000)).ok());
  EXPECT_EQ(r.client->GetCacheStats()->model_parses_running(), 0u);
}

// A server reads CAD files in the model check process and makes the model
// of the BRep it sends back; the samples are the bytes of the model read in
// process, for every fixture and format, with normals, faces and a density
// that depends on curvature.
TEST(ServerModels, ModelsReadInTheCheckProcessGiveTheSameBytesAsInProcess) {
  Running in_process = StartServer(LoopbackOptions());
  Running checked = StartServer(ModelServerOptions());
  std::vector<std::pair<std::string, std::string>> models;  // format, bytes
  for (auto solid : {cad::fixtures::Solid::kSphere, cad::fixtures::Solid::kCylinder,
                     cad::fixtures::Solid::kBoxWithHole}) {
    for (auto format : {ModelFormat::kStep, ModelFormat::kIges}) {
      auto bytes = cad::fixtures::SolidBytes(solid, format);
      ASSERT_TRUE(bytes.ok()) << bytes.status();
      models.emplace_back(format == ModelFormat::kStep ? "step" : "iges", *bytes);
    }
  }
  models.emplace_back("nurbs", cad::fixtures::NurbsPatchText());
  // Faces without area beside a square (issue 37: the face order and bytes
  // differed between the two paths).
  models.emplace_back("step", cad::fixtures::CollinearFacesStep(10, true));
  for (const auto& [format, bytes] : models) {
    std::vector<double> columns[2];
    std::vector<uint32_t> faces[2];
    int side = 0;
    for (Running* r : {&in_process, &checked}) {
      auto info = r->client->UploadModel(format, "model." + format, bytes);
      ASSERT_TRUE(info.ok()) << info.status();
      SampleRequest request = Request(info->spec(), 5000, 7);
      request.tree.density = "gaussian:floor=0.1";
      request.fields.normal = true;
      request.fields.face = true;
      auto s = r->client->Sample(request, [&](const StreamInfo&, const SampleBatch& batch) {
        for (size_t i = 0; i < batch.size(); ++i) {
          for (const auto* c : {&batch.u, &batch.v, &batch.x, &batch.y, &batch.z, &batch.nx,
                                &batch.ny, &batch.nz}) {
            columns[side].push_back((*c)[i]);
          }
          faces[side].push_back(batch.face[i]);
        }
        return absl::OkStatus();
      });
      ASSERT_TRUE(s.ok()) << format << ": " << s.status();
      ++side;
    }
    ASSERT_EQ(faces[0].size(), 5000u) << format;
    EXPECT_EQ(faces[0], faces[1]) << format;
    EXPECT_EQ(0,
              std::memcmp(columns[0].data(), columns[1].data(), columns[0].size() * sizeof(double)))
        << format << ": the BRep from the check process gave other samples";
  }
}

// The model check process passes on the loader's own refusals with their
// codes, in a message of bounded length.
TEST(ServerModels, TheModelCheckPassesOnTheLoadersOwnErrors) {
  Running r = StartServer(ModelServerOptions());
  auto truncated = cad::fixtures::SolidBytes(cad::fixtures::Solid::kSphere, ModelFormat::kStep);
  ASSERT_TRUE(truncated.ok());
  truncated->resize(truncated->size() / 2);
  auto info = r.client->UploadModel("step", "half.step", *truncated);
  ASSERT_TRUE(info.ok()) << info.status();
  const absl::Status refused = SampleStatus(*r.client, Request(info->spec(), 1000));
  EXPECT_EQ(refused.code(), absl::StatusCode::kInvalidArgument) << refused;
  EXPECT_LT(refused.message().size(), 1100u);
}

}  // namespace
}  // namespace sfc
