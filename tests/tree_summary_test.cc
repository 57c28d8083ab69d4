// A tree's summary is one fact (request/tree_summary.h, issue 38): the same
// tree described in process (the engine's SummarizeTree, as the CLI and
// Python get it) and by a server (its TreeInfo, read back by FromProto) has
// the same fields with the same values, for every kind of tree: a surface's
// curve tree (with depth-cap warnings and singular leaves), a mesh's and a
// CAD model's. A real server on a loopback port and the real client.
#include "request/tree_summary.h"

#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "client/sampler_client.h"
#include "engine/model_source.h"
#include "engine/sampling_engine.h"
#include "google/protobuf/util/message_differencer.h"
#include "grpcpp/create_channel.h"
#include "grpcpp/security/credentials.h"
#include "gtest/gtest.h"
#include "kinds/registered_kinds.h"
#include "proto/convert.h"
#include "tests/server_test_util.h"
#ifdef SFC_TEST_CAD
#include "cad/fixtures.h"
#endif

namespace sfc {
namespace {

namespace v1 = ::sfcsampler::v1;

using testing::LoopbackOptions;
using testing::Running;
using testing::StartServer;

void ExpectSameCells(const std::vector<TreeSummary::Cell>& a,
                     const std::vector<TreeSummary::Cell>& b, const char* what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].test, b[i].test) << what << i;
    EXPECT_EQ(a[i].u0, b[i].u0) << what << i;
    EXPECT_EQ(a[i].v0, b[i].v0) << what << i;
    EXPECT_EQ(a[i].size, b[i].size) << what << i;
    EXPECT_EQ(a[i].measured, b[i].measured) << what << i;
    EXPECT_EQ(a[i].limit, b[i].limit) << what << i;
  }
}

// Every field of the summary, value for value (doubles exactly: both come
// from the same tree, one through the wire).
void ExpectSameSummary(const TreeSummary& a, const TreeSummary& b) {
  EXPECT_EQ(a.kind, b.kind);
  EXPECT_EQ(a.key, b.key);
  EXPECT_EQ(a.key_with_grade, b.key_with_grade);
  EXPECT_EQ(a.canonical, b.canonical);
  EXPECT_EQ(a.grade, b.grade);
  EXPECT_EQ(a.cache_hit, b.cache_hit);
  EXPECT_EQ(a.refined, b.refined);
  EXPECT_EQ(a.leaves, b.leaves);
  EXPECT_EQ(a.bytes, b.bytes);
  EXPECT_EQ(a.min_depth, b.min_depth);
  EXPECT_EQ(a.max_depth, b.max_depth);
  EXPECT_EQ(a.tolerance, b.tolerance);
  EXPECT_EQ(a.flatness_capped_leaves, b.flatness_capped_leaves);
  EXPECT_EQ(a.mass_capped_leaves, b.mass_capped_leaves);
  ExpectSameCells(a.warnings, b.warnings, "warnings ");
  EXPECT_EQ(a.error_samples, b.error_samples);
  EXPECT_EQ(a.unresolved_error_samples, b.unresolved_error_samples);
  EXPECT_EQ(a.hidden_share, b.hidden_share);
  EXPECT_EQ(a.singular_leaves, b.singular_leaves);
  EXPECT_EQ(a.warped_leaves, b.warped_leaves);
  EXPECT_EQ(a.small_failing_leaves, b.small_failing_leaves);
  ExpectSameCells(a.singular, b.singular, "singular ");
}

// The summary of `local` in process (a fresh engine over files) and of
// `remote` (the same tree's spec as the server names it) from a fresh server;
// checks they agree, on the wire too, and returns the in-process one.
// `heap_bytes`: the tree's bytes include a parse measured on the heap (a CAD
// model's, kinds/cad/cad_module.cc), which differs between processes; every
// other field must still agree.
TreeSummary ExpectSameInProcessAndFromServer(Running& server, const TreeSpec& local,
                                             const TreeSpec& remote, uint64_t count,
                                             bool heap_bytes = false) {
  DirectTreeSource trees;
  FileModelSource files;
  const SamplingEngine engine(RegisteredSurfaceKinds(), EngineLimits{}, &trees, &files);
  auto prepared = engine.Prepare(local, count);
  EXPECT_TRUE(prepared.ok()) << prepared.status();
  if (!prepared.ok()) return {};
  const TreeSummary in_process = SummarizeTree(*prepared);

  // The server's message itself (the client hands over FromProto of it).
  auto stub = v1::Sampler::NewStub(grpc::CreateChannel(
      "127.0.0.1:" + std::to_string(server.server->port()), grpc::InsecureChannelCredentials()));
  grpc::ClientContext context;
  v1::PrepareRequest request;
  *request.mutable_tree() = ToProto(remote);
  request.set_count(count);
  v1::PrepareResponse response;
  const grpc::Status status = stub->Prepare(&context, request, &response);
  EXPECT_TRUE(status.ok()) << status.error_message();
  if (!status.ok()) return {};
  TreeSummary from_server = FromProto(response.tree());
  v1::TreeInfo sent = response.tree();
  if (heap_bytes) {
    EXPECT_GT(from_server.bytes, 0u);
    from_server.bytes = in_process.bytes;
    sent.set_bytes(in_process.bytes);
  }
  ExpectSameSummary(in_process, from_server);

  // The one mapping to the wire gives the server's message, and back again.
  v1::TreeInfo wire;
  ToProto(in_process, &wire);
  std::string differences;
  google::protobuf::util::MessageDifferencer differ;
  differ.ReportDifferencesToString(&differences);
  EXPECT_TRUE(differ.Compare(wire, sent)) << differences;
  v1::TreeInfo again;
  ToProto(from_server, &again);
  EXPECT_TRUE(google::protobuf::util::MessageDifferencer::Equals(again, sent));
  return in_process;
}

TreeSpec Spec(const std::string& surface) {
  TreeSpec spec;
  spec.surface = surface;
  return spec;
}

TEST(TreeSummary, ASurfaceTreeReadsTheSameInProcessAndFromAServer) {
  Running r = StartServer(LoopbackOptions());
  const TreeSummary torus =
      ExpectSameInProcessAndFromServer(r, Spec("torus"), Spec("torus"), 10000);
  EXPECT_EQ(torus.kind, "surface");
  EXPECT_FALSE(torus.cache_hit);
  EXPECT_GT(torus.leaves, 0u);
  EXPECT_GT(torus.max_depth, 0);
  EXPECT_GT(torus.tolerance, 0);
}

TEST(TreeSummary, DepthCapWarningsReadTheSameInProcessAndFromAServer) {
  Running r = StartServer(LoopbackOptions());
  TreeSpec capped = Spec("sphere");
  capped.options.depth_cap = 4;
  const TreeSummary sphere = ExpectSameInProcessAndFromServer(r, capped, capped, 100000);
  EXPECT_GT(sphere.flatness_capped_leaves + sphere.mass_capped_leaves, 0u);
  EXPECT_FALSE(sphere.warnings.empty());
}

TEST(TreeSummary, SingularLeavesReadTheSameInProcessAndFromAServer) {
  Running r = StartServer(LoopbackOptions());
  const TreeSummary hard =
      ExpectSameInProcessAndFromServer(r, Spec("superellipsoid"), Spec("superellipsoid"), 24576);
  EXPECT_GT(hard.warped_leaves, 0u);
  EXPECT_FALSE(hard.singular.empty());
  EXPECT_GT(hard.error_samples, 0);
}

// A density with a spot narrower than the tree's probes: the tree follows
// it, and what its leaves may still hide reaches the client as in process.
TEST(TreeSummary, AHiddenFeaturesShareReadsTheSameInProcessAndFromAServer) {
  Running r = StartServer(LoopbackOptions());
  TreeSpec spot = Spec("plane");
  spot.density = "expr:0.001+1000*((u-0.6180339887)^2+(v-0.4142135624)^2<1e-7)";
  const TreeSummary plane = ExpectSameInProcessAndFromServer(r, spot, spot, 10000);
  EXPECT_GT(plane.hidden_share, 0);
  EXPECT_LE(plane.hidden_share, 1.0 / 1024);
  const TreeSummary smooth =
      ExpectSameInProcessAndFromServer(r, Spec("torus"), Spec("torus"), 10000);
  EXPECT_EQ(smooth.hidden_share, 0);
}

// A model's file in process, its upload on the server: the same tree key,
// so the same summary.
TreeSummary ExpectSameModelSummary(const std::string& format, const std::string& bytes,
                                   uint64_t count, bool heap_bytes = false) {
  const std::string path = absl::StrCat(::testing::TempDir(), "tree_summary_model.", format);
  {
    std::ofstream out(path, std::ios::binary);
    out << bytes;
  }
  Running r = StartServer(LoopbackOptions());
  auto info = r.client->UploadModel(format, "model." + format, bytes);
  EXPECT_TRUE(info.ok()) << info.status();
  if (!info.ok()) return {};
  const TreeSummary summary = ExpectSameInProcessAndFromServer(
      r, Spec(absl::StrCat(format, ":", path)), Spec(info->spec()), count, heap_bytes);
  std::remove(path.c_str());
  return summary;
}

#ifdef SFC_TEST_MESH
TEST(TreeSummary, AMeshTreeReadsTheSameInProcessAndFromAServer) {
  std::string obj;
  constexpr int n = 8;  // an n x n grid of quads
  for (int i = 0; i <= n; ++i) {
    for (int j = 0; j <= n; ++j) absl::StrAppend(&obj, "v ", i, " ", j, " ", (i * j) % 3, "\n");
  }
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      const int a = i * (n + 1) + j + 1;
      absl::StrAppend(&obj, "f ", a, " ", a + n + 1, " ", a + n + 2, " ", a + 1, "\n");
    }
  }
  const TreeSummary mesh = ExpectSameModelSummary("obj", obj, 5000);
  EXPECT_EQ(mesh.kind, "mesh");
  EXPECT_GT(mesh.leaves, 0u);
  EXPECT_GT(mesh.bytes, 0u);
}
#endif

#ifdef SFC_TEST_CAD
TEST(TreeSummary, ACadModelTreeReadsTheSameInProcessAndFromAServer) {
  auto step = cad::fixtures::SolidBytes(cad::fixtures::Solid::kSphere, ModelFormat::kStep);
  ASSERT_TRUE(step.ok()) << step.status();
  const TreeSummary model = ExpectSameModelSummary("step", *step, 2000, /*heap_bytes=*/true);
  EXPECT_EQ(model.kind, "model");
  EXPECT_GT(model.leaves, 0u);
  EXPECT_GT(model.bytes, 0u);
}
#endif

}  // namespace
}  // namespace sfc
