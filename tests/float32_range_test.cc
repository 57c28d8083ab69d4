// Float32 columns a request asks for either hold its values (rounded, never
// changed past that) or the request is refused with INVALID_ARGUMENT naming
// the column (engine/float32_range.h): from the engine, as the CLI and Python
// run it in process, and from a server, before any sample is sent.
#include "engine/float32_range.h"

#include <cfloat>
#include <cmath>
#include <string>

#include "engine/sampling_engine.h"
#include "gtest/gtest.h"
#include "kinds/registered_kinds.h"
#include "tests/server_test_util.h"

namespace sfc {
namespace {

using testing::LoopbackOptions;
using testing::Running;
using testing::StartServer;

SampleRequest Request(const std::string& surface, const std::string& density, bool density_column,
                      uint64_t count = 2000) {
  SampleRequest r = testing::Request(surface, count, 3);
  r.tree.density = density;
  r.fields.density = density_column;
  r.fields.normal = r.fields.curve_position = true;
  return r;
}

// Every sample of `r` from the engine at `precision`, with the number of
// batches read before the first error.
absl::StatusOr<SampleBatch> Embedded(const SampleRequest& r, ColumnPrecision precision,
                                     int* batches = nullptr) {
  static DirectTreeSource source;
  SamplingEngine engine(RegisteredSurfaceKinds(), EngineLimits{}, &source);
  auto job = engine.Start(r, {}, precision);
  if (!job.ok()) return job.status();
  SampleBatch all;
  if (batches) *batches = 0;
  while (true) {
    auto n = job->cursor->Next(100, &all);
    if (!n.ok()) return n.status();
    if (*n == 0) return all;
    if (batches) ++*batches;
  }
}

// Every sample of `r` from a server at `precision`, with the number of
// batches received before the stream ended.
absl::StatusOr<SampleBatch> FromServer(const Running& running, const SampleRequest& r,
                                       ColumnPrecision precision, int* batches) {
  ClientOptions co;
  co.target = "127.0.0.1:" + std::to_string(running.server->port());
  co.stream.precision = precision;
  co.stream.batch_size = 100;
  auto client = SamplerClient::Connect(co);
  if (!client.ok()) return client.status();
  SampleBatch all;
  *batches = 0;
  auto s = (*client)->Sample(r, [&](const StreamInfo&, const SampleBatch& b) {
    all.Append(b);
    ++*batches;
    return absl::OkStatus();
  });
  if (!s.ok()) return s.status();
  return all;
}

void ExpectRefused(const absl::Status& s, const std::string& column, const std::string& todo) {
  EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument) << s;
  for (const std::string& part : {column, std::string("float64"), todo}) {
    EXPECT_NE(s.message().find(part), std::string::npos) << s.message() << " should say " << part;
  }
  EXPECT_LT(s.message().size(), 600u);
}

struct Case {
  const char* surface;
  const char* density;
  bool density_column;
  const char* column;  // what the message names
  const char* todo;    // what it says to scale
};
// Refused from the values the kind measures before any sample is made.
const Case kUpfront[] = {
    {"sphere:r=1e70", "uniform", false, "the x, y, z columns reach 1e+70", "scale the surface"},
    {"sphere:r=1e-50", "uniform", false, "the x, y, z columns span", "scale the surface"},
    {"expr:x=u;y=v;z=1e39*u*v", "uniform", false, "the z column reaches 1e+39",
     "scale the surface"},
    {"expr:x=u;y=v;z=0", "expr:1e300*u", true, "the density column reaches 1e+300",
     "scale the density"},
};
// A spike between the measured points: found only as the samples are made.
const Case kBackstop = {"expr:x=u;y=v;z=1e40*exp(-1e4*(u-0.53)^2)", "uniform", false,
                        "the z column's value", "scale the surface"};

TEST(Float32Range, RefusedBeforeAnySampleInProcess) {
  for (const Case& c : kUpfront) {
    const SampleRequest r = Request(c.surface, c.density, c.density_column);
    int batches = -1;
    const auto refused = Embedded(r, ColumnPrecision::kFloat32, &batches);
    ExpectRefused(refused.status(), c.column, c.todo);
    EXPECT_EQ(batches, -1) << c.surface << ": refused by Start, before a cursor";
    // float64 holds them: the same request is served.
    EXPECT_TRUE(Embedded(r, ColumnPrecision::kFloat64).ok()) << c.surface;
  }
}

TEST(Float32Range, RefusedBeforeAnySampleByTheServer) {
  Running running = StartServer(LoopbackOptions());
  for (const Case& c : kUpfront) {
    const SampleRequest r = Request(c.surface, c.density, c.density_column);
    int batches = 0;
    ExpectRefused(FromServer(running, r, ColumnPrecision::kFloat32, &batches).status(), c.column,
                  c.todo);
    EXPECT_EQ(batches, 0) << c.surface;
    EXPECT_TRUE(FromServer(running, r, ColumnPrecision::kFloat64, &batches).ok()) << c.surface;
  }
}

TEST(Float32Range, TheDensityIsCheckedOnlyWhenItsColumnIsAsked) {
  const SampleRequest r = Request("expr:x=u;y=v;z=0", "expr:1e300*u", false);
  EXPECT_TRUE(Embedded(r, ColumnPrecision::kFloat32).ok());
}

// The spike lies between the measured points, so the request starts, and
// ends at the first sample whose z float32 would make infinite; every
// batch before it holds only finite floats.
TEST(Float32Range, AValueNoMeasureForesawEndsTheRequestAtItsIndex) {
  const SampleRequest r = Request(kBackstop.surface, kBackstop.density, kBackstop.density_column);
  const auto all = Embedded(r, ColumnPrecision::kFloat64);
  ASSERT_TRUE(all.ok()) << all.status();
  size_t first = 0;
  while (first < all->size() && std::fabs(all->z[first]) <= FLT_MAX) ++first;
  ASSERT_LT(first, all->size()) << "the spike must overflow float32 at some sample";
  const std::string at = "at sample index " + std::to_string(all->index[first]) + " ";
  ExpectRefused(Embedded(r, ColumnPrecision::kFloat32).status(), kBackstop.column, at);

  Running running = StartServer(LoopbackOptions());
  int batches = 0;
  ExpectRefused(FromServer(running, r, ColumnPrecision::kFloat32, &batches).status(),
                kBackstop.column, at);
  EXPECT_LE(batches, static_cast<int>(first / 100));
}

// An ordinary float32 request is served, each value the float64 one rounded.
TEST(Float32Range, AnOrdinaryRequestIsTheFloat64OneRounded) {
  SampleRequest r = Request("torus", "gaussian:floor=0.1", true);
  const auto wide = Embedded(r, ColumnPrecision::kFloat64);
  const auto narrow = Embedded(r, ColumnPrecision::kFloat32);
  ASSERT_TRUE(wide.ok() && narrow.ok());
  EXPECT_EQ(narrow->x, wide->x);  // the engine's values; the front door rounds them
  Running running = StartServer(LoopbackOptions());
  int batches = 0;
  const auto wire = FromServer(running, r, ColumnPrecision::kFloat32, &batches);
  ASSERT_TRUE(wire.ok()) << wire.status();
  ASSERT_EQ(wire->size(), wide->size());
  for (size_t i = 0; i < wide->size(); ++i) {
    ASSERT_EQ(wire->x[i], static_cast<double>(static_cast<float>(wide->x[i])));
    ASSERT_EQ(wire->density[i], static_cast<double>(static_cast<float>(wide->density[i])));
  }
}

// A value just past FLT_MAX rounds to FLT_MAX (finite) when within half a
// step; the check follows the rounding, not the bound.
TEST(Float32Range, TheBatchCheckFollowsFloat32Rounding) {
  SampleBatch b;
  b.index = {7, 8};
  b.u = b.v = b.x = b.y = {0, 0};
  b.z = {std::nextafter(static_cast<double>(FLT_MAX), INFINITY), INFINITY};
  const SampleFields fields;  // u, v, x, y, z
  EXPECT_TRUE(CheckFloat32Batch(b, 0, fields).ok());  // rounds to FLT_MAX; inf stays inf
  b.z[1] = 1e39;
  ExpectRefused(CheckFloat32Batch(b, 0, fields), "the z column's value 1e+39 at sample index 8",
                "scale the surface");
  EXPECT_TRUE(CheckFloat32Batch(b, 2, fields).ok());  // only the samples appended are looked at
}

// Only the columns the client asked for are checked: the engine computes
// x, y, z for every request, and a request for u, v alone sends none of them
// (a review of stop 46 found such a request refused for its x).
TEST(Float32Range, ColumnsNotAskedForAreNotChecked) {
  SampleBatch b;
  b.index = {0};
  b.u = b.v = {0.5};
  b.x = {1e39};
  b.y = b.z = {0};
  SampleFields uv_only;
  uv_only.xyz = false;
  EXPECT_TRUE(CheckFloat32Batch(b, 0, uv_only).ok());
  ExpectRefused(CheckFloat32Batch(b, 0, SampleFields()), "the x column's value 1e+39",
                "scale the surface");
  // Through the engine: the surface reaches 1e39 in x, and u, v are asked for.
  SampleRequest r;
  r.tree.surface = "expr:x=u*1e39;y=v;z=0";
  r.count = 100;
  r.seed = 1;
  r.fields.xyz = false;
  const auto served = Embedded(r, ColumnPrecision::kFloat32);
  ASSERT_TRUE(served.ok()) << served.status();
  EXPECT_EQ(served->size(), 100u);
}

}  // namespace
}  // namespace sfc
