// The service end to end: a real sfcsampler server on a loopback port and the
// real client library, no mocks. Checks the behaviour users rely on
// (docs/SERVICE.md): slices and shards, resume, the shared cache, eviction,
// flow control, cancellation, and every bad input's status code.
#include <atomic>
#include <chrono>
#include <fstream>
#include <functional>
#include <limits>
#include <string>
#include <thread>

#include "client/sampler_client.h"
#include "engine/model_source.h"
#include "grpcpp/create_channel.h"
#include "gtest/gtest.h"
#include "kinds/registered_kinds.h"
#include "server/sampler_server.h"
#include "tests/server_test_util.h"

namespace sfc {
namespace {

namespace v1 = ::sfcsampler::v1;
using std::chrono::milliseconds;

using testing::ConnectWithDeadline;
using testing::LoopbackOptions;
using testing::Request;
using testing::Running;
using testing::StartServer;

// A stream far larger than flow-control buffers, so the server is still
// writing it when something happens, on a tree that builds at once (the
// plane needs few leaves when each may carry many samples).
SampleRequest LongStream(uint64_t count, uint64_t seed = 1) {
  SampleRequest r = Request("plane", count, seed);
  r.tree.options.rho = 1e6;
  return r;
}

// Stops `server` under its streams and starts a server with `next` on the
// same port (from another thread, as a restart would).
std::unique_ptr<SamplerServer> ReplaceOnSamePort(SamplerServer& server, ServerOptions next) {
  std::unique_ptr<SamplerServer> replacement;
  std::thread([&] {
    const int port = server.port();
    server.Shutdown(0, 0);
    next.address = "127.0.0.1:" + std::to_string(port);
    replacement = *SamplerServer::Start(next);
  }).join();
  return replacement;
}

// All samples of a request, as one batch.
absl::StatusOr<SampleBatch> Fetch(SamplerClient& client, const SampleRequest& request,
                                  StreamSummary* summary = nullptr) {
  SampleBatch all;
  auto s = client.Sample(request, [&](const StreamInfo&, const SampleBatch& b) {
    all.Append(b);
    return absl::OkStatus();
  });
  if (!s.ok()) return s.status();
  if (summary) *summary = *s;
  return all;
}

void ExpectEqual(const SampleBatch& a, const SampleBatch& b) {
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(a.index, b.index);
  EXPECT_EQ(a.u, b.u);
  EXPECT_EQ(a.v, b.v);
  EXPECT_EQ(a.x, b.x);
  EXPECT_EQ(a.y, b.y);
  EXPECT_EQ(a.z, b.z);
}

void ExpectStatus(const absl::Status& s, absl::StatusCode code, const std::string& mentions) {
  EXPECT_EQ(s.code(), code) << s;
  EXPECT_NE(s.message().find(mentions), std::string::npos)
      << s.message() << " should mention " << mentions;
}

TEST(Server, ShardsJoinToTheFullSetInOrder) {
  Running r = StartServer(LoopbackOptions());
  const SampleRequest full_request = Request("torus", 20000, 5);
  auto full = Fetch(*r.client, full_request);
  ASSERT_TRUE(full.ok()) << full.status();
  ASSERT_EQ(full->size(), 20000u);
  SampleBatch joined;
  for (uint64_t i = 0; i < 6; ++i) {
    auto shard = Fetch(*r.client, SamplerClient::Shard(full_request, i, 6));
    ASSERT_TRUE(shard.ok()) << shard.status();
    joined.Append(*shard);
  }
  ExpectEqual(joined, *full);
}

TEST(Server, AStreamCutByTheClientResumesByteIdentical) {
  Running r = StartServer(LoopbackOptions());
  const SampleRequest request = Request("eight", 30000, 2);
  auto uncut = Fetch(*r.client, request);
  ASSERT_TRUE(uncut.ok());
  // Cut after 7000 samples: the callback refuses more, which cancels.
  SampleBatch first;
  auto cut = r.client->Sample(request, [&](const StreamInfo&, const SampleBatch& b) {
    first.AppendFrom(b, 0, std::min<size_t>(b.size(), 7000 - first.size()));
    return first.size() < 7000 ? absl::OkStatus() : absl::CancelledError("cut");
  });
  ASSERT_EQ(cut.status().code(), absl::StatusCode::kCancelled);
  auto rest =
      Fetch(*r.client, SamplerClient::Range(request, first.index.back() + 1, request.count));
  ASSERT_TRUE(rest.ok());
  first.Append(*rest);
  ExpectEqual(first, *uncut);
}

TEST(Server, TheClientResumesAcrossAServerRestart) {
  ServerOptions options = LoopbackOptions();
  auto server = *SamplerServer::Start(options);
  const int port = server->port();
  ClientOptions co;
  co.target = "127.0.0.1:" + std::to_string(port);
  co.stream.batch_size = 1000;
  co.resume_backoff_seconds = 0.3;
  auto client = *SamplerClient::Connect(co);
  const SampleRequest request = LongStream(2'000'000, 8);  // still streaming when the server dies
  auto reference = Fetch(*client, request);
  ASSERT_TRUE(reference.ok());

  std::atomic<bool> restarted{false};
  std::unique_ptr<SamplerServer> second;
  SampleBatch got;
  StreamSummary summary;
  auto result = client->Sample(request, [&](const StreamInfo&, const SampleBatch& b) {
    got.index.insert(got.index.end(), b.index.begin(), b.index.end());
    got.u.insert(got.u.end(), b.u.begin(), b.u.end());
    if (!restarted && got.size() >= 50000) {
      restarted = true;
      second = ReplaceOnSamePort(*server, options);
    }
    return absl::OkStatus();
  });
  ASSERT_TRUE(result.ok()) << result.status();
  EXPECT_GE(result->resumes, 1);
  EXPECT_EQ(got.index, reference->index);
  EXPECT_EQ(got.u, reference->u);
}

TEST(Server, AResumeOnAServerOfAnotherReleaseFailsInsteadOfMixingSets) {
  ServerOptions options = LoopbackOptions();
  options.algorithm_version = "sfcsampler-older-release";
  auto server = *SamplerServer::Start(options);
  const int port = server->port();
  ClientOptions co;
  co.target = "127.0.0.1:" + std::to_string(port);
  co.stream.batch_size = 1000;
  co.resume_backoff_seconds = 0.3;
  auto client = *SamplerClient::Connect(co);
  std::unique_ptr<SamplerServer> upgraded;
  uint64_t received = 0;
  bool restarted = false;
  auto result =
      client->Sample(LongStream(2'000'000, 8), [&](const StreamInfo&, const SampleBatch& b) {
        received += b.size();
        if (!restarted && received >= 50000) {
          // The replica is replaced by one of the current release mid-stream.
          restarted = true;
          upgraded = ReplaceOnSamePort(*server, LoopbackOptions());
        }
        return absl::OkStatus();
      });
  ExpectStatus(result.status(), absl::StatusCode::kFailedPrecondition, "algorithm version");
  ExpectStatus(result.status(), absl::StatusCode::kFailedPrecondition, "sfcsampler-older-release");
}

// All samples of a request from the embedded engine, in process.
SampleBatch Embedded(const SampleRequest& request) {
  DirectTreeSource source;
  SamplingEngine engine(RegisteredSurfaceKinds(), {}, &source);
  auto job = engine.Start(request);
  EXPECT_TRUE(job.ok()) << job.status();
  SampleBatch local;
  if (job.ok()) {
    while (*job->cursor->Next(4096, &local) > 0) {
    }
  }
  return local;
}

TEST(Server, EmbeddedAndWireSamplesAreIdentical) {
  Running r = StartServer(LoopbackOptions());
  SampleRequest request = Request("monkey_saddle", 5000, 3);
  request.tree.density = "gaussian:floor=0.1";
  request.region = Region::Box({-0.5, -0.5, -1}, {0.5, 0.5, 1});
  const SampleBatch local = Embedded(request);
  auto wire = Fetch(*r.client, request);
  ASSERT_TRUE(wire.ok());
  ExpectEqual(*wire, local);
}

// Every value column, through the pipelined stream, in each encoding and
// precision: float64 carries the embedded engine's bits, float32 exactly
// their float rounding. Small batches make many messages pass the pipeline.
TEST(Server, EveryEncodingAndPrecisionCarriesTheEmbeddedEnginesSamples) {
  for (int depth : {0, 1, 3}) {
    ServerOptions options = LoopbackOptions();
    options.stream_pipeline_depth = depth;
    Running r = StartServer(options);
    SampleRequest request = Request("torus", 30000, 8);
    request.tree.density = "gaussian:floor=0.1";
    request.fields.normal = request.fields.density = request.fields.curve_position = true;
    const SampleBatch local = Embedded(request);
    for (auto encoding : {ColumnEncoding::kRaw, ColumnEncoding::kPacked}) {
      for (auto precision : {ColumnPrecision::kFloat64, ColumnPrecision::kFloat32}) {
        ClientOptions co;
        co.target = "127.0.0.1:" + std::to_string(r.server->port());
        co.stream.encoding = encoding;
        co.stream.precision = precision;
        co.stream.batch_size = 777;
        auto wire = Fetch(**SamplerClient::Connect(co), request);
        ASSERT_TRUE(wire.ok()) << wire.status();
        ASSERT_EQ(wire->index, local.index);
        for (auto column : {&SampleBatch::u, &SampleBatch::v, &SampleBatch::x, &SampleBatch::y,
                            &SampleBatch::z, &SampleBatch::nx, &SampleBatch::ny, &SampleBatch::nz,
                            &SampleBatch::density, &SampleBatch::curve_position}) {
          ASSERT_EQ(((*wire).*column).size(), local.size());
          for (size_t i = 0; i < local.size(); ++i) {
            const double expected =
                precision == ColumnPrecision::kFloat64
                    ? (local.*column)[i]
                    : static_cast<double>(static_cast<float>((local.*column)[i]));
            ASSERT_EQ(((*wire).*column)[i], expected) << "sample " << i << " depth " << depth;
          }
        }
      }
    }
  }
}

TEST(Server, ASecondRequestHitsAndEightConcurrentFirstRequestsBuildOnce) {
  Running r = StartServer(LoopbackOptions());
  std::vector<std::thread> threads;
  std::atomic<int> ok{0};
  for (int i = 0; i < 8; ++i) {
    threads.emplace_back([&, i] {
      if (Fetch(*r.client, Request("eight", 200000, i)).ok()) ++ok;
    });
  }
  for (auto& t : threads) t.join();
  EXPECT_EQ(ok.load(), 8);
  auto stats = r.client->GetCacheStats();
  ASSERT_TRUE(stats.ok());
  EXPECT_EQ(stats->builds(), 1u);
  EXPECT_EQ(stats->misses(), 1u);
  EXPECT_EQ(stats->hits() + stats->waits(), 7u);

  StreamSummary summary;
  ASSERT_TRUE(Fetch(*r.client, Request("eight", 200000, 99), &summary).ok());
  EXPECT_TRUE(summary.header.tree.cache_hit);
  EXPECT_EQ(r.client->GetCacheStats()->builds(), 1u);
}

TEST(Server, ALargerCountRefinesTheCachedTree) {
  Running r = StartServer(LoopbackOptions());
  TreeSpec spec;
  spec.surface = "torus";
  ASSERT_TRUE(r.client->Prepare(spec, 1000).ok());
  StreamSummary summary;
  ASSERT_TRUE(Fetch(*r.client, Request("torus", 100000), &summary).ok());
  EXPECT_TRUE(summary.header.tree.refined);
  const auto stats = *r.client->GetCacheStats();
  EXPECT_EQ(stats.builds(), 1u);
  EXPECT_EQ(stats.refinements(), 1u);
}

TEST(Server, EvictionUnderASmallBudgetLosesNoInFlightStream) {
  ServerOptions options = LoopbackOptions();
  options.cache_bytes = 1 << 20;  // smaller than any of these trees
  ClientOptions co;
  co.stream.batch_size = 500;
  Running r = StartServer(options, co);
  const SampleRequest slow = Request("sphere", 60000, 4);
  auto reference = Fetch(*r.client, slow);
  ASSERT_TRUE(reference.ok());
  SampleBatch got;
  bool evicted = false;
  auto result = r.client->Sample(slow, [&](const StreamInfo&, const SampleBatch& b) {
    got.index.insert(got.index.end(), b.index.begin(), b.index.end());
    got.x.insert(got.x.end(), b.x.begin(), b.x.end());
    if (!evicted) {
      evicted = true;  // other jobs push this stream's tree out of the cache
      EXPECT_TRUE(Fetch(*r.client, Request("torus", 60000)).ok());
      EXPECT_TRUE(Fetch(*r.client, Request("eight", 60000)).ok());
      EXPECT_GE(r.client->GetCacheStats()->evictions(), 2u);
    }
    return absl::OkStatus();
  });
  ASSERT_TRUE(result.ok()) << result.status();
  EXPECT_EQ(got.index, reference->index);
  EXPECT_EQ(got.x, reference->x);
}

TEST(Server, ASlowReaderDoesNotMakeTheServerGenerateAhead) {
  ClientOptions co;
  co.stream.batch_size = 16384;  // 655 KB a message in float64
  Running r = StartServer(LoopbackOptions(), co);
  const uint64_t n = 4'000'000;
  int batches = 0;
  double streamed_after_stall = 0;
  auto result = r.client->Sample(Request("plane", n), [&](const StreamInfo&, const SampleBatch&) {
    if (++batches == 2) {
      std::this_thread::sleep_for(milliseconds(1000));
      streamed_after_stall = r.server->metrics().samples_streamed();
      return absl::CancelledError("done");
    }
    return absl::OkStatus();
  });
  EXPECT_EQ(result.status().code(), absl::StatusCode::kCancelled);
  // Only what HTTP/2 flow control admits was produced: a few MB, not 4 M samples.
  EXPECT_LT(streamed_after_stall, 40 * 16384.0);
  EXPECT_GE(streamed_after_stall, 2 * 16384.0);
}

TEST(Server, ACancelledStreamIsFreedAtOnce) {
  ClientOptions co;
  co.stream.batch_size = 1000;
  Running r = StartServer(LoopbackOptions(), co);
  auto result =
      r.client->Sample(Request("sphere", 1'000'000), [&](const StreamInfo&, const SampleBatch&) {
        EXPECT_EQ(r.server->service().active_streams(), 1u);
        return absl::CancelledError("enough");
      });
  EXPECT_EQ(result.status().code(), absl::StatusCode::kCancelled);
  // "At once": well within 200 ms of the cancel, not after the 10^6 samples.
  const auto until = std::chrono::steady_clock::now() + milliseconds(200);
  while (r.server->service().active_streams() != 0 && std::chrono::steady_clock::now() < until) {
    std::this_thread::sleep_for(milliseconds(1));
  }
  EXPECT_EQ(r.server->service().active_streams(), 0u);
  EXPECT_LT(r.server->metrics().samples_streamed(), 1'000'000.0);
}


// A request whose tree takes a minute to build unless stopped: a pole the
// tree refines towards until the leaf budget of HeavyOptions().
SampleRequest HeavyBuild(const std::string& pole_at = "0.3") {
  return Request("expr:x=u;y=v;z=1/(u-" + pole_at + ")", 100'000'000);
}
ServerOptions HeavyOptions() {
  ServerOptions o = LoopbackOptions();
  o.limits.max_tree_leaves = uint64_t{1} << 25;
  return o;
}

// Waits up to `seconds` for `done`; true if it came.
bool Within(double seconds, const std::function<bool()>& done) {
  const auto until =
      std::chrono::steady_clock::now() + milliseconds(static_cast<int>(seconds * 1000));
  while (!done()) {
    if (std::chrono::steady_clock::now() > until) return false;
    std::this_thread::sleep_for(milliseconds(10));
  }
  return true;
}

TEST(Server, ABuildNobodyWaitsForAnyMoreStopsAndFreesItsSlot) {
  Running r = StartServer(HeavyOptions());
  auto impatient = ConnectWithDeadline(*r.server, 0.5);
  const auto start = std::chrono::steady_clock::now();
  ExpectStatus(Fetch(*impatient, HeavyBuild()).status(), absl::StatusCode::kDeadlineExceeded, "");
  EXPECT_LT(std::chrono::steady_clock::now() - start, milliseconds(3000));
  // The server notices the client is gone, stops the build, frees the slot.
  EXPECT_TRUE(Within(5, [&] {
    const TreeCacheStats s = r.server->cache().stats();
    return s.builds_running == 0 && r.server->service().active_streams() == 0;
  }));
  const TreeCacheStats s = r.server->cache().stats();
  EXPECT_EQ(s.builds_stopped, 1u);
  EXPECT_EQ(s.builds, 0u);
  EXPECT_EQ(s.builds_failed, 0u);  // a stopped build is not remembered as a failure
}

TEST(Server, TheServersRequestDeadlineStopsABuildNobodyElseWaitsFor) {
  ServerOptions options = HeavyOptions();
  options.request_deadline_seconds = 0.5;
  ClientOptions co;
  co.max_resumes = 0;
  Running r = StartServer(options, co);
  const auto start = std::chrono::steady_clock::now();
  ExpectStatus(Fetch(*r.client, HeavyBuild()).status(), absl::StatusCode::kDeadlineExceeded,
               "request deadline of 0.5 s");
  EXPECT_LT(std::chrono::steady_clock::now() - start, milliseconds(3000));
  EXPECT_TRUE(Within(5, [&] { return r.server->cache().stats().builds_running == 0; }));
  EXPECT_EQ(r.server->cache().stats().builds_stopped, 1u);
}

TEST(Server, AWaiterLeavesAtItsOwnDeadlineWhileTheBuildGoesOnForOthers) {
  Running r = StartServer(HeavyOptions());
  absl::Status patient_status;
  // The patient client's deadline outlives the impatient one's by seconds.
  auto patient = ConnectWithDeadline(*r.server, 3);
  std::thread first([&] { patient_status = Fetch(*patient, HeavyBuild()).status(); });
  ASSERT_TRUE(Within(5, [&] { return r.server->cache().stats().builds_running == 1; }));

  auto impatient = ConnectWithDeadline(*r.server, 0.3);
  ExpectStatus(Fetch(*impatient, HeavyBuild()).status(), absl::StatusCode::kDeadlineExceeded, "");
  // The impatient client joined the same build and left it; the build goes on.
  EXPECT_EQ(r.server->cache().stats().waits, 1u);
  EXPECT_EQ(r.server->cache().stats().builds_running, 1u);
  first.join();
  EXPECT_EQ(patient_status.code(), absl::StatusCode::kDeadlineExceeded) << patient_status;
  EXPECT_TRUE(Within(5, [&] { return r.server->cache().stats().builds_running == 0; }));
}

TEST(Server, BuildsBeyondTheQueueAreTurnedAwayAndNamedTheLimit) {
  ServerOptions options = HeavyOptions();
  options.max_concurrent_builds = 1;
  options.max_queued_builds = 0;
  Running r = StartServer(options);
  auto client = ConnectWithDeadline(*r.server, 2);
  std::thread first([&] { (void)Fetch(*client, HeavyBuild("0.3")); });
  ASSERT_TRUE(Within(5, [&] { return r.server->cache().stats().builds_running == 1; }));
  ExpectStatus(Fetch(*r.client, HeavyBuild("0.4")).status(), absl::StatusCode::kResourceExhausted,
               "max_queued_builds");
  // A cached tree needs no builder: it is still served.
  first.join();
  EXPECT_EQ(r.server->cache().stats().builds_rejected, 1u);
  auto stats = r.client->GetCacheStats();
  ASSERT_TRUE(stats.ok());
  EXPECT_EQ(stats->max_concurrent_builds(), 1u);
  EXPECT_EQ(stats->max_queued_builds(), 0u);
}

TEST(Server, ADensityWithFeaturesTheTreeCannotSeeIsRefusedAsAnInvalidArgument) {
  // A strip 1e-4 wide between the Gauss nodes of every cell down to the depth
  // cap (docs/ALGORITHM.md, "Features narrower than the probes").
  Running r = StartServer(LoopbackOptions());
  SampleRequest request = Request("plane", 100000);
  request.tree.density = "expr:0.001+1000*(u>0.30014142135623731)*(u<0.30024142135623731)";
  request.tree.options.depth_cap = 10;
  ExpectStatus(Fetch(*r.client, request).status(), absl::StatusCode::kInvalidArgument,
               "narrower than the curve tree can see");
}

TEST(Server, AFailedBuildIsRememberedAndNotRepeated) {
  ServerOptions options = LoopbackOptions();
  options.limits.max_tree_leaves = 1000;
  Running r = StartServer(options);
  SampleRequest fine = Request("torus", 1000);
  fine.tree.options.tolerance = 1e-6;  // needs far more than 1000 leaves
  ExpectStatus(Fetch(*r.client, fine).status(), absl::StatusCode::kResourceExhausted, "max_leaves");
  const absl::Status again = Fetch(*r.client, fine).status();
  ExpectStatus(again, absl::StatusCode::kResourceExhausted, "max_leaves");
  ExpectStatus(again, absl::StatusCode::kResourceExhausted, "remembers failed builds");
  const TreeCacheStats s = r.server->cache().stats();
  EXPECT_EQ(s.builds_failed, 1u);
  EXPECT_EQ(s.failure_hits, 1u);
  EXPECT_EQ(s.misses, 1u);
}

TEST(Server, ShutdownStopsARunningBuild) {
  ClientOptions co;
  co.max_resumes = 0;  // see the server's answer, not a retry
  Running r = StartServer(HeavyOptions(), co);
  absl::Status status;
  std::thread waiting([&] { status = Fetch(*r.client, HeavyBuild()).status(); });
  ASSERT_TRUE(Within(5, [&] { return r.server->cache().stats().builds_running == 1; }));
  const auto start = std::chrono::steady_clock::now();
  r.server->Shutdown(0.2, 0);
  EXPECT_LT(std::chrono::steady_clock::now() - start, milliseconds(3000));
  waiting.join();
  EXPECT_EQ(status.code(), absl::StatusCode::kUnavailable) << status;
}

// The batch size a refusal names is accepted when asked for, whether the
// tree was cold at the refusal and warm at the ask: at every remainder of the
// message size by the bytes a sample takes (12 here), so the header's few
// bytes of cache state would cross a boundary at some of them.
TEST(Server, TheLargestBatchSizeARefusalNamesIsAccepted) {
  for (int extra = 0; extra < 12; ++extra) {
    ServerOptions options = LoopbackOptions();
    options.max_message_bytes = 65536 + extra;
    ClientOptions co;
    co.max_resumes = 0;
    co.stream.batch_size = 1 << 20;
    co.stream.precision = ColumnPrecision::kFloat32;
    Running r = StartServer(options, co);
    SampleRequest request = LongStream(3'000'000);
    request.fields.uv = false;
    const absl::Status refused = Fetch(*r.client, request).status();  // on a cold tree
    ExpectStatus(refused, absl::StatusCode::kInvalidArgument, "ask for at most ");
    const std::string m(refused.message());
    const std::string ask = "ask for at most ";
    const uint32_t hinted = static_cast<uint32_t>(std::stoul(m.substr(m.find(ask) + ask.size())));
    ClientOptions asks = co;
    asks.stream.batch_size = hinted;
    asks.target = "127.0.0.1:" + std::to_string(r.server->port());
    auto client = *SamplerClient::Connect(asks);
    size_t first = 0;
    const auto result = client->Sample(request, [&](const StreamInfo&, const SampleBatch& b) {
      first = b.size();
      return absl::CancelledError("one batch is enough");
    });
    EXPECT_EQ(result.status().code(), absl::StatusCode::kCancelled)
        << "extra " << extra << ": " << result.status();
    EXPECT_EQ(first, hinted) << "extra " << extra;
  }
}

TEST(Server, AStockClientReceivesEveryColumnWithinItsDefaultMessageLimit) {
  Running r = StartServer(LoopbackOptions());
  // A plain generated stub on a default channel: 4 MiB receive limit.
  auto channel = grpc::CreateChannel("127.0.0.1:" + std::to_string(r.server->port()),
                                     grpc::InsecureChannelCredentials());
  auto stub = v1::Sampler::NewStub(channel);
  v1::SampleRequest request;
  request.mutable_tree()->set_surface("torus");
  request.mutable_tree()->set_density("gaussian:floor=0.1");
  request.set_count(300000);
  request.set_normals(true);
  request.set_density(true);
  request.set_curve_position(true);
  grpc::ClientContext context;
  auto reader = stub->Sample(&context, request);
  v1::SampleResponse response;
  uint64_t samples = 0;
  size_t largest = 0;
  while (reader->Read(&response)) {
    samples += response.batch().size();
    largest = std::max(largest, response.ByteSizeLong());
  }
  const grpc::Status status = reader->Finish();
  EXPECT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(samples, 300000u);
  EXPECT_LE(largest, size_t{4} << 20);
  EXPECT_GT(largest, size_t{2} << 20);  // batches are as large as fit, not tiny

  // Asking for more than fits names the cap and the largest batch that fits.
  ClientOptions co;
  co.target = "127.0.0.1:" + std::to_string(r.server->port());
  co.stream.batch_size = 100000;
  auto client = *SamplerClient::Connect(co);
  SampleRequest all = Request("torus", 300000);
  all.fields.normal = all.fields.density = all.fields.curve_position = true;
  ExpectStatus(Fetch(*client, all).status(), absl::StatusCode::kInvalidArgument,
               "max_message_bytes");
}

// Columns a client leaves off (omit_uv, omit_xyz) do not travel, the
// others are the full stream's, and a request that leaves no value column is
// refused.
TEST(Server, ColumnsLeftOffDoNotTravelAndTheRestAreTheFullStreams) {
  Running r = StartServer(LoopbackOptions());
  auto channel = grpc::CreateChannel("127.0.0.1:" + std::to_string(r.server->port()),
                                     grpc::InsecureChannelCredentials());
  auto stub = v1::Sampler::NewStub(channel);
  auto stream = [&](bool omit_uv, bool omit_xyz, bool normals, size_t* bytes,
                    grpc::Status* status) {
    v1::SampleRequest request;
    request.mutable_tree()->set_surface("torus");
    request.set_count(20000);
    request.set_batch_size(5000);
    request.set_precision(v1::PRECISION_FLOAT32);
    request.set_column_encoding(v1::COLUMN_ENCODING_RAW);
    request.set_normals(normals);
    request.set_omit_uv(omit_uv);
    request.set_omit_xyz(omit_xyz);
    grpc::ClientContext context;
    auto reader = stub->Sample(&context, request);
    v1::SampleResponse response;
    std::vector<v1::RawColumns> columns;
    *bytes = 0;
    while (reader->Read(&response)) {
      *bytes += response.batch().ByteSizeLong();
      columns.push_back(response.batch().raw());
    }
    *status = reader->Finish();
    return columns;
  };
  size_t all_bytes = 0, xyz_bytes = 0, normal_bytes = 0, none_bytes = 0;
  grpc::Status status;
  const auto all = stream(false, false, true, &all_bytes, &status);
  ASSERT_TRUE(status.ok()) << status.error_message();
  const auto xyz = stream(true, false, false, &xyz_bytes, &status);
  ASSERT_TRUE(status.ok()) << status.error_message();
  const auto normals = stream(true, true, true, &normal_bytes, &status);
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_EQ(all.size(), 4u);
  ASSERT_EQ(xyz.size(), all.size());
  ASSERT_EQ(normals.size(), all.size());
  for (size_t i = 0; i < all.size(); ++i) {
    EXPECT_TRUE(xyz[i].u().empty() && xyz[i].v().empty() && xyz[i].nx().empty());
    EXPECT_EQ(xyz[i].x(), all[i].x());
    EXPECT_EQ(xyz[i].z(), all[i].z());
    EXPECT_TRUE(normals[i].u().empty() && normals[i].x().empty() && normals[i].z().empty());
    EXPECT_EQ(normals[i].nx(), all[i].nx());
    EXPECT_EQ(normals[i].nz(), all[i].nz());
  }
  // 8 columns of 4 bytes against 3: the bytes follow the columns sent.
  EXPECT_LT(xyz_bytes, all_bytes * 3 / 8 + 1000);
  EXPECT_LT(normal_bytes, all_bytes * 3 / 8 + 1000);

  stream(true, true, false, &none_bytes, &status);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(status.error_message().find("no value column"), std::string::npos)
      << status.error_message();
}

// Issue 37: rho has explicit presence on the wire. A 0 a client sends is
// refused, not read as "unset"; an old client's unset field still means 1.
TEST(Server, AnExplicitRhoOfZeroIsRefusedAndAnUnsetOneMeansOne) {
  Running r = StartServer(LoopbackOptions());
  auto channel = grpc::CreateChannel("127.0.0.1:" + std::to_string(r.server->port()),
                                     grpc::InsecureChannelCredentials());
  auto stub = v1::Sampler::NewStub(channel);
  auto first_x = [&](std::optional<double> rho, grpc::Status* status) {
    v1::SampleRequest request;
    request.mutable_tree()->set_surface("torus");
    if (rho) request.mutable_tree()->set_rho(*rho);
    request.set_count(500);
    grpc::ClientContext context;
    auto reader = stub->Sample(&context, request);
    v1::SampleResponse response;
    std::string x;
    while (reader->Read(&response)) {
      if (x.empty() && response.has_batch()) x = response.batch().SerializeAsString();
    }
    *status = reader->Finish();
    return x;
  };
  grpc::Status status;
  first_x(0.0, &status);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(status.error_message().find("rho"), std::string::npos) << status.error_message();
  const std::string unset = first_x(std::nullopt, &status);
  ASSERT_TRUE(status.ok()) << status.error_message();
  const std::string one = first_x(1.0, &status);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(unset, one);
  EXPECT_FALSE(unset.empty());
  // A 0 from the C++ client library (which sends what it is given) too.
  SampleRequest zero = Request("torus", 500);
  zero.tree.options.rho = 0;
  auto fetched = Fetch(*r.client, zero);
  EXPECT_EQ(fetched.status().code(), absl::StatusCode::kInvalidArgument);
}

// The C++ client asks for what SampleFields keeps and gets exactly that.
TEST(Server, TheClientReceivesOnlyTheColumnsItAskedFor) {
  Running r = StartServer(LoopbackOptions());
  SampleRequest full = Request("torus", 3000);
  SampleRequest positions = full;
  positions.fields.uv = false;
  auto a = Fetch(*r.client, full);
  auto b = Fetch(*r.client, positions);
  ASSERT_TRUE(a.ok() && b.ok()) << a.status() << b.status();
  EXPECT_TRUE(b->u.empty() && b->v.empty());
  EXPECT_EQ(b->index, a->index);
  EXPECT_EQ(b->x, a->x);
  EXPECT_EQ(b->y, a->y);
  EXPECT_EQ(b->z, a->z);
}

TEST(Server, EveryBadInputGetsItsStatusCode) {
  ServerOptions options = LoopbackOptions();
  options.limits.max_count = 1'000'000;
  options.limits.max_tree_leaves = 20'000;
  options.limits.max_spec_length = 200;
  options.max_batch_size = 10000;
  ClientOptions co;
  co.stream.batch_size = 1000;
  Running r = StartServer(options, co);
  auto fetch = [&](SampleRequest q) { return Fetch(*r.client, q).status(); };
  const auto kInvalid = absl::StatusCode::kInvalidArgument;
  ExpectStatus(fetch(Request("klein", 10)), kInvalid, "unknown surface");
  ExpectStatus(fetch(Request("expr:x=u;y=v;z=sqrt(u-0.5)", 10)), kInvalid, "not finite");
  SampleRequest negative = Request("plane", 10);
  negative.tree.density = "expr:u-0.5";
  ExpectStatus(fetch(negative), kInvalid, ">= 0");
  SampleRequest zero = Request("plane", 10);
  zero.tree.density = "expr:0";
  ExpectStatus(fetch(zero), kInvalid, "integrates");
  SampleRequest region = Request("sphere", 10);
  region.region = Region::ParameterRect(0.4, 0.2, 0, 1);
  ExpectStatus(fetch(region), kInvalid, "empty");
  ExpectStatus(fetch(Request("sphere", 0)), kInvalid, "count");
  ExpectStatus(fetch(Request("sphere", 2'000'000)), kInvalid, "max_count");
  ExpectStatus(fetch(Request("expr:x=u;y=v;z=" + std::string(300, '1'), 10)), kInvalid,
               "max_spec_length");
  ExpectStatus(fetch(Request("expr:x=u;y=v;z=1/(u-0.3)", 1'000'000)),
               absl::StatusCode::kResourceExhausted, "max_leaves");
  ExpectStatus(fetch(Request("expr:x=u;y=v;z=u**v", 10)), kInvalid, "position");

  ClientOptions big_batches;
  big_batches.target = "127.0.0.1:" + std::to_string(r.server->port());
  big_batches.stream.batch_size = 20000;
  auto client = *SamplerClient::Connect(big_batches);
  ExpectStatus(Fetch(*client, Request("sphere", 10)).status(), kInvalid, "max_batch_size");
}

TEST(Server, StreamsBeyondTheConcurrencyLimitAreResourceExhausted) {
  ServerOptions options = LoopbackOptions();
  options.max_concurrent_streams = 1;
  ClientOptions co;
  co.stream.batch_size = 1000;
  Running r = StartServer(options, co);
  absl::Status second;
  // The server is still writing the first stream when the second request comes.
  auto first = r.client->Sample(LongStream(4'000'000), [&](const StreamInfo&, const SampleBatch&) {
    second = Fetch(*r.client, Request("torus", 10)).status();
    return absl::CancelledError("checked");
  });
  EXPECT_EQ(first.status().code(), absl::StatusCode::kCancelled) << first.status();
  ExpectStatus(second, absl::StatusCode::kResourceExhausted, "max_concurrent_streams");
}

TEST(Server, TheServerDeadlineEndsLongStreams) {
  ServerOptions options = LoopbackOptions();
  options.request_deadline_seconds = 0.2;
  ClientOptions co;
  co.stream.batch_size = 100;
  Running r = StartServer(options, co);
  // A tree that builds at once, and a stream that runs past the deadline.
  auto result = r.client->Sample(LongStream(4'000'000), [&](const StreamInfo&, const SampleBatch&) {
    std::this_thread::sleep_for(milliseconds(2));
    return absl::OkStatus();
  });
  ExpectStatus(result.status(), absl::StatusCode::kDeadlineExceeded, "resume after the last index");
}

// A blue request whose relaxation would take many seconds (about 7 s a
// million samples on one core), on a tree built beforehand so that only the
// relaxation runs when the request comes.
SampleRequest LongBlueRelaxation() {
  SampleRequest r = Request("sphere", 1'000'000, 3);
  r.sequence = SequenceKind::kBlue;
  return r;
}
void WarmTreeOf(SamplerClient& client, const SampleRequest& request) {
  SampleRequest warm = request;
  warm.sequence = SequenceKind::kJittered;
  warm.begin = 0, warm.end = 1;
  ASSERT_TRUE(Fetch(client, warm).ok());
}
uint64_t StreamMemoryReserved(SamplerClient& client) {
  auto stats = client.GetCacheStats();
  EXPECT_TRUE(stats.ok()) << stats.status();
  return stats.ok() ? stats->stream_memory_reserved() : ~uint64_t{0};
}

// A blue set is relaxed whole, whatever part of it is asked: a set whose
// relaxation is over the stream memory is refused with advice that can
// help (fewer samples, not a smaller range), and one over the blue limit with
// the engine's own reason, not a memory refusal.
TEST(Server, ABlueSetTooLargeIsRefusedWithAdviceThatHelps) {
  ServerOptions options = LoopbackOptions();
  options.stream_memory_bytes = 1 << 20;
  options.limits.max_blue_count = 100'000;
  Running r = StartServer(options);
  SampleRequest over_memory = Request("sphere", 50'000, 3);
  over_memory.sequence = SequenceKind::kBlue;
  over_memory.begin = 0, over_memory.end = 10;
  const absl::Status memory = Fetch(*r.client, over_memory).status();
  ExpectStatus(memory, absl::StatusCode::kResourceExhausted, "stream_memory_bytes");
  ExpectStatus(memory, absl::StatusCode::kResourceExhausted, "fewer samples (count)");
  EXPECT_EQ(memory.message().find("smaller index range"), std::string::npos) << memory;
  SampleRequest over_limit = over_memory;
  over_limit.count = 200'000;
  ExpectStatus(Fetch(*r.client, over_limit).status(), absl::StatusCode::kInvalidArgument,
               "max_blue_count");
}

TEST(Server, TheServerDeadlineStopsABlueRelaxationAndFreesItsMemory) {
  ServerOptions options = LoopbackOptions();
  options.request_deadline_seconds = 0.5;
  ClientOptions co;
  co.max_resumes = 0;
  Running r = StartServer(options, co);
  WarmTreeOf(*r.client, LongBlueRelaxation());
  const auto start = std::chrono::steady_clock::now();
  ExpectStatus(Fetch(*r.client, LongBlueRelaxation()).status(),
               absl::StatusCode::kDeadlineExceeded, "blue-noise set relaxed");
  // Promptly: a generous bound, far below the relaxation's own time.
  EXPECT_LT(std::chrono::steady_clock::now() - start, milliseconds(5000));
  EXPECT_EQ(StreamMemoryReserved(*r.client), 0u);
  EXPECT_EQ(r.server->service().active_streams(), 0u);
}

TEST(Server, AClientThatGivesUpStopsABlueRelaxationAndFreesItsMemory) {
  ClientOptions co;
  co.max_resumes = 0;
  Running r = StartServer(LoopbackOptions(), co);
  WarmTreeOf(*r.client, LongBlueRelaxation());
  auto impatient = ConnectWithDeadline(*r.server, 0.5, co);
  const auto start = std::chrono::steady_clock::now();
  EXPECT_EQ(Fetch(*impatient, LongBlueRelaxation()).status().code(),
            absl::StatusCode::kDeadlineExceeded);
  // The server sees the client gone, stops the relaxation and frees its slot
  // and its reservation, long before the relaxation would have ended.
  EXPECT_TRUE(Within(5, [&] {
    return r.server->service().active_streams() == 0 && StreamMemoryReserved(*r.client) == 0;
  }));
  EXPECT_LT(std::chrono::steady_clock::now() - start, milliseconds(5500));
}

// A timeout of 0 or less would cut every stream at once, NaN or infinity
// never: the server refuses to start, naming the flag. Valid ones are
// reported by GetCacheStats.
TEST(Server, TimeoutsMustBeFiniteAndPositive) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  for (double bad : {0.0, -1.0, nan, inf}) {
    ServerOptions write = LoopbackOptions();
    write.write_timeout_seconds = bad;
    ExpectStatus(SamplerServer::Start(write).status(), absl::StatusCode::kInvalidArgument,
                 "--write-timeout must be a finite number of seconds > 0");
    ServerOptions upload = LoopbackOptions();
    upload.upload_idle_timeout_seconds = bad;
    ExpectStatus(SamplerServer::Start(upload).status(), absl::StatusCode::kInvalidArgument,
                 "--upload-idle-timeout must be a finite number of seconds > 0");
    ServerOptions rate = LoopbackOptions();
    rate.upload_min_bytes_per_second = bad;
    ExpectStatus(SamplerServer::Start(rate).status(), absl::StatusCode::kInvalidArgument,
                 "--upload-min-rate must be a finite number of bytes a second > 0");
  }
  ServerOptions options = LoopbackOptions();
  options.write_timeout_seconds = 7.5;
  options.upload_idle_timeout_seconds = 0.25;
  options.upload_min_bytes_per_second = 1234.5;
  Running r = StartServer(options);
  auto stats = r.client->GetCacheStats();
  ASSERT_TRUE(stats.ok()) << stats.status();
  EXPECT_EQ(stats->write_timeout_seconds(), 7.5);
  EXPECT_EQ(stats->upload_idle_timeout_seconds(), 0.25);
  EXPECT_EQ(stats->upload_min_bytes_per_second(), 1234.5);
}

// With any pipeline depth (0: none): the producer stops at the full queue,
// the RPC thread's blocked write is what the watchdog cuts.
TEST(Server, AReaderThatStopsReadingIsCutAndFreesItsSlot) {
  for (int depth : {0, 1, 2, 4}) {
    ServerOptions options = LoopbackOptions();
    options.write_timeout_seconds = 0.3;
    options.max_concurrent_streams = 1;
    options.stream_pipeline_depth = depth;
    ClientOptions co;
    co.stream.batch_size = 16384;
    Running r = StartServer(options, co);
    std::atomic<bool> freed{false};
    std::atomic<double> stalled{0};
    auto result =
        r.client->Sample(Request("plane", 4'000'000), [&](const StreamInfo&, const SampleBatch&) {
          // Stop reading: the server's writes block on flow control. Its slot
          // must come free while this client still holds the stream open.
          const auto until = std::chrono::steady_clock::now() + milliseconds(5000);
          while (std::chrono::steady_clock::now() < until && !freed) {
            freed = r.server->service().active_streams() == 0;
            std::this_thread::sleep_for(milliseconds(10));
          }
          stalled = r.server->metrics().stalled_streams();
          return absl::OkStatus();
        });
    EXPECT_TRUE(freed) << "the stalled stream still held its slot after 5 s, depth " << depth;
    EXPECT_EQ(stalled.load(), 1.0) << "depth " << depth;
    EXPECT_FALSE(result.ok());
    // Generation stopped with the queue: far fewer than the 4 M samples.
    EXPECT_LT(r.server->metrics().samples_streamed(), 2'000'000.0);
    // The slot serves the next client at once.
    EXPECT_TRUE(Fetch(*r.client, Request("torus", 1000)).ok());
  }
}

TEST(Server, AModelIsUploadedOnceAndNamedByItsHash) {
  ServerOptions options = LoopbackOptions();
  options.max_model_bytes = 3 << 20;
  Running r = StartServer(options);
  const std::string path = ::testing::TempDir() + "/server_test_model.obj";
  std::string content;
  for (int i = 0; i < 200000; ++i)
    content += "v " + std::to_string(i) + " 0 0\n";  // > 1 MiB: several chunks
  std::ofstream(path) << content;
  auto spec = r.client->EnsureModel("obj:" + path);
  ASSERT_TRUE(spec.ok()) << spec.status();
  EXPECT_EQ(*spec, "obj:sha256=" + Sha256Hex(content));
  // Again, by path or by hash: found, not sent again.
  EXPECT_EQ(*r.client->EnsureModel("obj:" + path), *spec);
  EXPECT_EQ(*r.client->EnsureModel(*spec), *spec);
  EXPECT_EQ(r.server->models().stats().uploads, 1u);
  EXPECT_EQ(r.server->models().stats().already_stored, 0u);
  auto stats = *r.client->GetCacheStats();
  EXPECT_EQ(stats.models(), 1u);
  EXPECT_EQ(stats.model_bytes(), content.size());
  EXPECT_EQ(stats.max_model_bytes(), options.max_model_bytes);
  // Unknown hashes and oversized models say what to do.
  ExpectStatus(r.client->EnsureModel("obj:sha256=" + std::string(64, '0')).status(),
               absl::StatusCode::kNotFound, "upload it again");
  ExpectStatus(r.client->UploadModel("ply", "huge.ply", std::string(4 << 20, 'x')).status(),
               absl::StatusCode::kResourceExhausted, "max_model_bytes");
  ExpectStatus(r.client->UploadModel("dwg", "a.dwg", "x").status(),
               absl::StatusCode::kInvalidArgument, "unknown model format");
  EXPECT_EQ(r.server->models().stats().rejected, 1u);
}

TEST(Server, TheStreamHeaderSaysWhereTheParameterisationIsSingularAndThePrecisionReached) {
  Running r = StartServer(LoopbackOptions());
  StreamSummary hard, smooth;
  ASSERT_TRUE(Fetch(*r.client, Request("superellipsoid", 24576), &hard).ok());
  ASSERT_TRUE(Fetch(*r.client, Request("torus", 24576), &smooth).ok());
  const TreeSummary& t = hard.header.tree;
  EXPECT_GT(t.warped_leaves, 0u);
  ASSERT_FALSE(t.singular.empty());
  for (const TreeSummary::Cell& w : t.singular) {
    EXPECT_EQ(w.test, "singular");
    // The superellipsoid's area element blows up where cos or sin of an
    // angle vanishes: on the parameter lines u, v in {0, 1/4, 1/2, 3/4, 1}.
    auto on_quarter_line = [](double lo, double hi) {
      for (double q : {0.0, 0.25, 0.5, 0.75, 1.0}) {
        if (lo <= q && q <= hi) return true;
      }
      return false;
    };
    EXPECT_TRUE(on_quarter_line(w.u0, w.u0 + w.size) || on_quarter_line(w.v0, w.v0 + w.size))
        << w.u0 << " " << w.v0 << " " << w.size;
  }
  // The precision reached stays below the jittered set's own discrepancy
  // (about N^(1/4) = 12.5 samples here), on the hard surface as on a smooth one.
  EXPECT_LT(t.error_samples, 12.5);
  EXPECT_EQ(smooth.header.tree.singular_leaves, 0u);
  EXPECT_EQ(smooth.header.tree.warped_leaves, 0u);
  EXPECT_LT(smooth.header.tree.error_samples, 12.5);
}

TEST(Server, ATokenIsRequiredWhenSetButHealthStaysOpen) {
  ServerOptions options = LoopbackOptions();
  options.token = "s3cret";
  Running r = StartServer(options);
  ExpectStatus(Fetch(*r.client, Request("sphere", 10)).status(), absl::StatusCode::kUnauthenticated,
               "Bearer");
  EXPECT_TRUE(*r.client->CheckHealth());
  ClientOptions co;
  co.target = "127.0.0.1:" + std::to_string(r.server->port());
  co.token = "s3cret";
  auto authorised = *SamplerClient::Connect(co);
  EXPECT_TRUE(Fetch(*authorised, Request("sphere", 10)).ok());
}

TEST(Server, AGracefulShutdownFinishesStreamsAndTurnsNewCallsAway) {
  ClientOptions co;
  co.stream.batch_size = 1000;
  co.max_resumes = 0;
  Running r = StartServer(LoopbackOptions(), co);
  const SampleRequest request = Request("sphere", 300000, 3);
  std::thread stopper;
  absl::Status refused;
  uint64_t received = 0;
  auto result = r.client->Sample(request, [&](const StreamInfo&, const SampleBatch& b) {
    received += b.size();
    if (!stopper.joinable()) {
      stopper = std::thread([&] { r.server->Shutdown(30, 1); });
      // Wait until the server has started draining, then ask for more.
      while (r.client->CheckHealth().value_or(false)) std::this_thread::sleep_for(milliseconds(5));
      refused = Fetch(*r.client, Request("torus", 10)).status();
    }
    std::this_thread::sleep_for(milliseconds(1));  // a slow reader
    return absl::OkStatus();
  });
  stopper.join();
  ASSERT_TRUE(result.ok()) << result.status();
  EXPECT_EQ(received, 300000u);
  ExpectStatus(refused, absl::StatusCode::kUnavailable, "shutting down");
}

TEST(Server, Float32PayloadsCarryTheSameSamplesRounded) {
  ClientOptions co;
  co.stream.precision = ColumnPrecision::kFloat32;
  Running r = StartServer(LoopbackOptions(), co);
  auto f32 = Fetch(*r.client, Request("torus", 3000));
  ClientOptions co64;
  co64.target = "127.0.0.1:" + std::to_string(r.server->port());
  auto f64 = Fetch(**SamplerClient::Connect(co64), Request("torus", 3000));
  ASSERT_TRUE(f32.ok() && f64.ok());
  ASSERT_EQ(f32->size(), f64->size());
  for (size_t i = 0; i < f32->size(); ++i) {
    ASSERT_EQ(f32->x[i], static_cast<double>(static_cast<float>(f64->x[i])));
  }
}

}  // namespace
}  // namespace sfc
