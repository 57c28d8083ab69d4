// The wire conversions of proto/convert.h on their own: a batch survives the
// round trip bit for bit, and a malformed batch is refused before the client
// allocates for it.
#include "proto/convert.h"

#include "gtest/gtest.h"

namespace sfc {
namespace {

SampleBatch ThreeSamples() {
  SampleBatch b;
  b.index = {7, 8, 9};
  b.u = {0.1, 0.2, 0.3};
  b.v = {0.4, 0.5, 0.6};
  b.x = {1.0 / 3, -2.5, 1e-300};
  b.y = {0, -0.0, 4};
  b.z = {5, 6, 7};
  return b;
}

TEST(AppendFromProto, GivesBackTheBatchThatToProtoSent) {
  const SampleBatch sent = ThreeSamples();
  v1::SampleBatch wire;
  ToProto(sent, SampleFields{}, v1::PRECISION_FLOAT64, &wire);
  SampleBatch got;
  ASSERT_TRUE(AppendFromProto(wire, SampleFields{}, &got).ok());
  EXPECT_EQ(got.index, sent.index);
  for (auto column : {&SampleBatch::u, &SampleBatch::v, &SampleBatch::x, &SampleBatch::y, &SampleBatch::z}) {
    ASSERT_EQ((got.*column).size(), (sent.*column).size());
    for (size_t i = 0; i < sent.size(); ++i) {
      EXPECT_EQ(std::signbit((got.*column)[i]), std::signbit((sent.*column)[i]));
      EXPECT_EQ((got.*column)[i], (sent.*column)[i]);
    }
  }
}

// Found by tools/fuzz.sh (proto_batch_fuzzer): a 10-byte message claiming
// 4 * 10^8 samples made the client append that many indices before it
// noticed the empty columns.
TEST(AppendFromProto, RefusesASizeItsColumnsDoNotHoldBeforeAppendingAnything) {
  v1::SampleBatch wire;
  wire.set_size(1 << 20);
  wire.mutable_f64();
  SampleBatch got;
  const absl::Status status = AppendFromProto(wire, SampleFields{}, &got);
  EXPECT_EQ(status.code(), absl::StatusCode::kDataLoss);
  EXPECT_EQ(got.size(), 0u);
  EXPECT_TRUE(got.u.empty());
}

TEST(AppendFromProto, RefusesAMissingRequestedColumn) {
  v1::SampleBatch wire;
  ToProto(ThreeSamples(), SampleFields{}, v1::PRECISION_FLOAT32, &wire);
  SampleFields with_normals;
  with_normals.normal = true;
  SampleBatch got;
  EXPECT_EQ(AppendFromProto(wire, with_normals, &got).code(), absl::StatusCode::kDataLoss);
}

TEST(AppendFromProto, CarriesTheFaceAndTriangleColumnsAndRefusesAShortOne) {
  SampleBatch sent = ThreeSamples();
  sent.face = {0, 4, 4294967295u};
  sent.triangle = {2, 1, 0};
  SampleFields fields;
  fields.face = fields.triangle = true;
  v1::SampleBatch wire;
  ToProto(sent, fields, v1::PRECISION_FLOAT32, &wire);
  SampleBatch got;
  ASSERT_TRUE(AppendFromProto(wire, fields, &got).ok());
  EXPECT_EQ(got.face, sent.face);
  EXPECT_EQ(got.triangle, sent.triangle);

  wire.mutable_triangle()->RemoveLast();
  SampleBatch short_one;
  EXPECT_EQ(AppendFromProto(wire, fields, &short_one).code(), absl::StatusCode::kDataLoss);
}

TEST(MaxSamplesPerMessage, AMessageOfThatManySamplesWithModelColumnsFitsTheCap) {
  SampleFields fields;
  fields.normal = fields.face = fields.triangle = true;
  const size_t cap = 1 << 16;
  const uint32_t n = MaxSamplesPerMessage(fields, v1::PRECISION_FLOAT64, true, 0, cap);
  ASSERT_GT(n, 0u);
  SampleBatch b;
  for (uint32_t i = 0; i < n; ++i) {
    b.index.push_back(uint64_t{1} << 40 | (i * 7919u));  // not consecutive: indices listed
    for (auto* c : {&b.u, &b.v, &b.x, &b.y, &b.z, &b.nx, &b.ny, &b.nz}) c->push_back(i);
    b.face.push_back(UINT32_MAX);
    b.triangle.push_back(UINT32_MAX);
  }
  v1::SampleResponse response;
  ToProto(b, fields, v1::PRECISION_FLOAT64, response.mutable_batch());
  EXPECT_LE(response.ByteSizeLong(), cap);
}

}  // namespace
}  // namespace sfc
