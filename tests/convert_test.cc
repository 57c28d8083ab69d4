// The wire conversions of proto/convert.h on their own: a batch survives the
// round trip bit for bit, and a malformed batch is refused before the client
// allocates for it.
#include "proto/convert.h"

#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>

#include "gtest/gtest.h"

namespace sfc {
namespace {

// The stream options a batch is encoded with in these tests.
StreamOptions Stream(ColumnPrecision precision, ColumnEncoding encoding = ColumnEncoding::kPacked) {
  StreamOptions stream;
  stream.precision = precision;
  stream.encoding = encoding;
  return stream;
}

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
  ToProto(sent, SampleFields{}, Stream(ColumnPrecision::kFloat64), &wire);
  SampleBatch got;
  ASSERT_TRUE(AppendFromProto(wire, SampleFields{}, &got).ok());
  EXPECT_EQ(got.index, sent.index);
  for (auto column :
       {&SampleBatch::u, &SampleBatch::v, &SampleBatch::x, &SampleBatch::y, &SampleBatch::z}) {
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
  ToProto(ThreeSamples(), SampleFields{}, Stream(ColumnPrecision::kFloat32), &wire);
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
  ToProto(sent, fields, Stream(ColumnPrecision::kFloat32), &wire);
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
  const uint32_t n = MaxSamplesPerMessage(fields, ColumnPrecision::kFloat64, true, 0, cap);
  ASSERT_GT(n, 0u);
  SampleBatch b;
  for (uint32_t i = 0; i < n; ++i) {
    b.index.push_back(uint64_t{1} << 40 | (i * 7919u));  // not consecutive: indices listed
    for (auto* c : {&b.u, &b.v, &b.x, &b.y, &b.z, &b.nx, &b.ny, &b.nz}) c->push_back(i);
    b.face.push_back(UINT32_MAX);
    b.triangle.push_back(UINT32_MAX);
  }
  v1::SampleResponse response;
  ToProto(b, fields, Stream(ColumnPrecision::kFloat64), response.mutable_batch());
  EXPECT_LE(response.ByteSizeLong(), cap);
}

const std::array<SampleBatch::ValueColumn, 10>& kValueColumns = SampleBatch::ValueColumns();

uint64_t Bits(double d) {
  uint64_t b;
  std::memcpy(&b, &d, sizeof b);
  return b;
}

// A batch with every column, of values drawn over the whole double range
// (random bit patterns that are finite) plus the awkward ones: signed
// zeros, subnormals, the extremes, values that round to float infinity or
// to a float subnormal.
SampleBatch EveryColumn(size_t n, uint64_t seed, bool consecutive) {
  std::mt19937_64 rng(seed);
  const double special[] = {0.0, -0.0, 5e-324, -5e-324, std::numeric_limits<double>::min(),
                            std::numeric_limits<double>::max(), -std::numeric_limits<double>::max(),
                            1e300, 1e-40, 1.0 / 3, 0.1, -2.5};
  SampleBatch b;
  for (size_t i = 0; i < n; ++i) {
    b.index.push_back(consecutive ? 1000 + i : rng() >> 1);
    for (auto column : kValueColumns) {
      double d;
      if (rng() % 4 == 0) {
        d = special[rng() % (sizeof special / sizeof special[0])];
      } else {
        do {
          const uint64_t r = rng();
          std::memcpy(&d, &r, sizeof d);
        } while (!std::isfinite(d));
      }
      (b.*column).push_back(d);
    }
    b.face.push_back(static_cast<uint32_t>(rng()));
    b.triangle.push_back(static_cast<uint32_t>(rng()));
  }
  return b;
}

SampleFields AllFields() {
  SampleFields f;
  f.normal = f.density = f.curve_position = f.face = f.triangle = true;
  return f;
}

TEST(RawColumns, RoundTripBitExactlyForEveryColumnAndPrecision) {
  const SampleFields fields = AllFields();
  for (uint64_t seed = 1; seed <= 20; ++seed) {
    const SampleBatch sent = EveryColumn(1 + seed * 37, seed, seed % 2 == 0);
    for (auto precision : {ColumnPrecision::kFloat64, ColumnPrecision::kFloat32}) {
      v1::SampleBatch wire;
      ToProto(sent, fields, Stream(precision, ColumnEncoding::kRaw), &wire);
      ASSERT_TRUE(wire.has_raw());
      SampleBatch got;
      ASSERT_TRUE(AppendFromProto(wire, fields, &got).ok());
      ASSERT_EQ(got.index, sent.index);
      EXPECT_EQ(got.face, sent.face);
      EXPECT_EQ(got.triangle, sent.triangle);
      for (auto column : kValueColumns) {
        ASSERT_EQ((got.*column).size(), sent.size());
        for (size_t i = 0; i < sent.size(); ++i) {
          // float64 exactly; float32 exactly the float the value rounds to.
          const double expected = precision == ColumnPrecision::kFloat64
                                      ? (sent.*column)[i]
                                      : static_cast<double>(static_cast<float>((sent.*column)[i]));
          ASSERT_EQ(Bits((got.*column)[i]), Bits(expected)) << (sent.*column)[i];
        }
      }
    }
  }
}

TEST(RawColumns, LongBatchesRoundTripAndAnIndexOutOfStepAnywhereIsListed) {
  // Columns are converted, and indices checked for steps of one, in blocks
  // of 1024 samples: lengths around the block's edges, and one index out of
  // step in the first, a middle or the last block.
  const SampleFields fields = AllFields();
  for (size_t n : {1023, 1024, 1025, 2048, 3001}) {
    for (size_t bad : {size_t{0}, n / 2, n - 1, n}) {  // n: none out of step
      SampleBatch sent = EveryColumn(n, n, /*consecutive=*/true);
      if (bad < n) sent.index[bad] += 7;
      for (auto precision : {ColumnPrecision::kFloat64, ColumnPrecision::kFloat32}) {
        for (auto encoding : {ColumnEncoding::kRaw, ColumnEncoding::kPacked}) {
          v1::SampleBatch wire;
          ToProto(sent, fields, Stream(precision, encoding), &wire);
          EXPECT_EQ(wire.index_size(), bad < n ? static_cast<int>(n) : 0) << n << " " << bad;
          SampleBatch got;
          ASSERT_TRUE(AppendFromProto(wire, fields, &got).ok());
          ASSERT_EQ(got.index, sent.index);
          for (auto column : kValueColumns) {
            ASSERT_EQ((got.*column).size(), n);
            for (size_t i = 0; i < n; ++i) {
              const double expected =
                  precision == ColumnPrecision::kFloat64
                      ? (sent.*column)[i]
                      : static_cast<double>(static_cast<float>((sent.*column)[i]));
              ASSERT_EQ(Bits((got.*column)[i]), Bits(expected)) << n << " " << i;
            }
          }
        }
      }
    }
  }
}

TEST(RawColumns, AreLittleEndianIeeeValuesBackToBack) {
  // The layout the proto documents, checked byte by byte against the value's
  // bits rather than against our own decoder.
  SampleBatch b = ThreeSamples();
  v1::SampleBatch wire64, wire32;
  ToProto(b, SampleFields{}, Stream(ColumnPrecision::kFloat64, ColumnEncoding::kRaw), &wire64);
  ToProto(b, SampleFields{}, Stream(ColumnPrecision::kFloat32, ColumnEncoding::kRaw), &wire32);
  EXPECT_EQ(wire32.raw().precision(), v1::PRECISION_FLOAT32);
  ASSERT_EQ(wire64.raw().x().size(), 3 * 8u);
  ASSERT_EQ(wire32.raw().x().size(), 3 * 4u);
  for (size_t i = 0; i < 3; ++i) {
    const uint64_t bits64 = Bits(b.x[i]);
    const float f = static_cast<float>(b.x[i]);
    uint32_t bits32;
    std::memcpy(&bits32, &f, sizeof bits32);
    for (size_t k = 0; k < 8; ++k) {
      EXPECT_EQ(static_cast<unsigned char>(wire64.raw().x()[8 * i + k]),
                (bits64 >> (8 * k)) & 0xff);
    }
    for (size_t k = 0; k < 4; ++k) {
      EXPECT_EQ(static_cast<unsigned char>(wire32.raw().x()[4 * i + k]),
                (bits32 >> (8 * k)) & 0xff);
    }
  }
}

TEST(RawColumns, DecodeToTheSameBatchAsPackedColumns) {
  const SampleFields fields = AllFields();
  const SampleBatch sent = EveryColumn(500, 7, false);
  for (auto precision : {ColumnPrecision::kFloat64, ColumnPrecision::kFloat32}) {
    v1::SampleBatch raw, packed;
    ToProto(sent, fields, Stream(precision, ColumnEncoding::kRaw), &raw);
    ToProto(sent, fields, Stream(precision, ColumnEncoding::kPacked), &packed);
    // The same bytes either way, give or take the precision field.
    EXPECT_LE(raw.ByteSizeLong(), packed.ByteSizeLong() + 2);
    SampleBatch a, b;
    ASSERT_TRUE(AppendFromProto(raw, fields, &a).ok());
    ASSERT_TRUE(AppendFromProto(packed, fields, &b).ok());
    for (auto column : kValueColumns) {
      ASSERT_EQ((a.*column).size(), (b.*column).size());
      for (size_t i = 0; i < a.size(); ++i) ASSERT_EQ(Bits((a.*column)[i]), Bits((b.*column)[i]));
    }
  }
}

TEST(RawColumns, AShortRaggedOrUnknownColumnIsDataLossBeforeAnythingIsAppended) {
  const SampleFields fields = AllFields();
  const SampleBatch sent = EveryColumn(10, 3, true);
  v1::SampleBatch wire;
  ToProto(sent, fields, Stream(ColumnPrecision::kFloat64, ColumnEncoding::kRaw), &wire);
  {
    v1::SampleBatch ragged = wire;
    ragged.mutable_raw()->mutable_u()->pop_back();  // 79 bytes for 10 samples
    SampleBatch got;
    EXPECT_EQ(AppendFromProto(ragged, fields, &got).code(), absl::StatusCode::kDataLoss);
    EXPECT_EQ(got.size(), 0u);
  }
  {
    v1::SampleBatch short_nz = wire;
    short_nz.mutable_raw()->mutable_nz()->resize(8 * 9);
    SampleBatch got;
    EXPECT_EQ(AppendFromProto(short_nz, fields, &got).code(), absl::StatusCode::kDataLoss);
  }
  {
    v1::SampleBatch claims_float32 = wire;  // 8-byte values read as 4-byte ones
    claims_float32.mutable_raw()->set_precision(v1::PRECISION_FLOAT32);
    SampleBatch got;
    EXPECT_EQ(AppendFromProto(claims_float32, fields, &got).code(), absl::StatusCode::kDataLoss);
  }
  {
    v1::SampleBatch unknown = wire;
    unknown.mutable_raw()->set_precision(static_cast<v1::Precision>(7));
    SampleBatch got;
    EXPECT_EQ(AppendFromProto(unknown, fields, &got).code(), absl::StatusCode::kDataLoss);
  }
}

TEST(MaxSamplesPerMessage, ARawMessageOfThatManySamplesFitsTheCap) {
  const SampleFields fields = AllFields();
  for (auto precision : {ColumnPrecision::kFloat64, ColumnPrecision::kFloat32}) {
    for (size_t cap : {size_t{4096}, size_t{1} << 16, size_t{4} << 20}) {
      const uint32_t n = MaxSamplesPerMessage(fields, precision, true, 0, cap);
      ASSERT_GT(n, 0u);
      SampleBatch b = EveryColumn(n, 11, false);
      v1::SampleResponse response;
      ToProto(b, fields, Stream(precision, ColumnEncoding::kRaw), response.mutable_batch());
      EXPECT_LE(response.ByteSizeLong(), cap);
    }
  }
}

// The stream options travel beside the request and read back as sent; a
// request that names none gets the wire's defaults.
TEST(FromProto, ReadsTheStreamOptionsBesideTheRequest) {
  SampleRequest request;
  request.count = 1000;
  request.seed = 7;
  StreamOptions stream = Stream(ColumnPrecision::kFloat32, ColumnEncoding::kRaw);
  stream.batch_size = 777;
  const auto call = FromProto(ToProto(request, stream));
  ASSERT_TRUE(call.ok()) << call.status();
  EXPECT_EQ(call->request.count, 1000u);
  EXPECT_EQ(call->request.seed, 7u);
  EXPECT_EQ(call->stream.precision, ColumnPrecision::kFloat32);
  EXPECT_EQ(call->stream.batch_size, 777u);
  EXPECT_EQ(call->stream.encoding, ColumnEncoding::kRaw);
  const v1::SampleRequest wire = ToProto(request);
  EXPECT_EQ(wire.precision(), v1::PRECISION_FLOAT64);
  EXPECT_EQ(wire.batch_size(), 0u);
  EXPECT_EQ(wire.column_encoding(), v1::COLUMN_ENCODING_PACKED);
  const auto defaults = FromProto(wire);
  ASSERT_TRUE(defaults.ok()) << defaults.status();
  EXPECT_EQ(defaults->stream.precision, ColumnPrecision::kFloat64);
  EXPECT_EQ(defaults->stream.batch_size, 0u);
  EXPECT_EQ(defaults->stream.encoding, ColumnEncoding::kPacked);
}

TEST(FromProto, AnUnknownColumnEncodingIsInvalidArgument) {
  v1::SampleRequest request;
  request.set_count(10);
  request.set_column_encoding(static_cast<v1::ColumnEncoding>(9));
  EXPECT_EQ(FromProto(request).status().code(), absl::StatusCode::kInvalidArgument);
}

// SampleFields::uv and ::xyz leave columns off the wire; a batch from a
// server that predates them still carries every column, and the client
// keeps only what it asked for. Every subset, both encodings and precisions.
TEST(WireColumns, OnlyTheAskedForColumnsTravelAndArrive) {
  const SampleBatch sent = EveryColumn(50, 5, true);
  for (int mask = 0; mask < 8; ++mask) {
    SampleFields fields;
    fields.uv = mask & 1;
    fields.xyz = mask & 2;
    fields.normal = mask & 4;
    if (WireValueColumns(fields) == 0) continue;
    for (auto encoding : {ColumnEncoding::kPacked, ColumnEncoding::kRaw}) {
      for (auto precision : {ColumnPrecision::kFloat64, ColumnPrecision::kFloat32}) {
        v1::SampleBatch narrow, old_server;
        ToProto(sent, fields, Stream(precision, encoding), &narrow);
        SampleFields everything = fields;
        everything.uv = everything.xyz = everything.normal = true;
        ToProto(sent, everything, Stream(precision, encoding), &old_server);
        EXPECT_LT(narrow.ByteSizeLong(), old_server.ByteSizeLong() + (mask == 7 ? 1 : 0));
        for (const v1::SampleBatch* wire : {&narrow, &old_server}) {
          SampleBatch got;
          ASSERT_TRUE(AppendFromProto(*wire, fields, &got).ok()) << mask;
          EXPECT_EQ(got.index, sent.index);
          EXPECT_EQ(got.u.size(), fields.uv ? sent.size() : 0u);
          EXPECT_EQ(got.x.size(), fields.xyz ? sent.size() : 0u);
          EXPECT_EQ(got.nx.size(), fields.normal ? sent.size() : 0u);
          EXPECT_TRUE(got.density.empty());
        }
        // The message's size follows the columns it carries.
        const size_t width = precision == ColumnPrecision::kFloat32 ? 4 : 8;
        EXPECT_GE(narrow.ByteSizeLong(), WireValueColumns(fields) * width * sent.size());
        EXPECT_LT(narrow.ByteSizeLong(),
                  (WireValueColumns(fields) * width + 1) * sent.size() + 100);
      }
    }
  }
}

TEST(WireColumns, AMessageOfTheMostThatFitWithoutUvFitsTheCapAndHoldsMore) {
  SampleFields all, positions;
  positions.uv = false;
  for (auto precision : {ColumnPrecision::kFloat64, ColumnPrecision::kFloat32}) {
    const size_t cap = 1 << 16;
    const uint32_t n = MaxSamplesPerMessage(positions, precision, true, 0, cap);
    EXPECT_GT(n, MaxSamplesPerMessage(all, precision, true, 0, cap) * 4 /
                     3);  // 48 or 28 bytes a sample against 32 or 20
    const SampleBatch b = EveryColumn(n, 13, false);
    v1::SampleResponse response;
    ToProto(b, positions, Stream(precision, ColumnEncoding::kRaw), response.mutable_batch());
    EXPECT_LE(response.ByteSizeLong(), cap);
  }
}

// A column that fails after others were appended takes them back: the
// batch holds exactly what it held before.
TEST(WireColumns, ALateBadColumnLeavesTheBatchAsItWas) {
  const SampleFields fields = AllFields();
  const SampleBatch first = EveryColumn(7, 1, true);
  v1::SampleBatch good, bad;
  ToProto(first, fields, Stream(ColumnPrecision::kFloat64, ColumnEncoding::kRaw), &good);
  ToProto(EveryColumn(9, 2, true), fields, Stream(ColumnPrecision::kFloat64, ColumnEncoding::kRaw),
          &bad);
  bad.mutable_triangle()->RemoveLast();
  SampleBatch got;
  ASSERT_TRUE(AppendFromProto(good, fields, &got).ok());
  EXPECT_EQ(AppendFromProto(bad, fields, &got).code(), absl::StatusCode::kDataLoss);
  EXPECT_EQ(got.index, first.index);
  for (auto column : kValueColumns) EXPECT_EQ((got.*column).size(), first.size());
  EXPECT_EQ(got.face, first.face);
  EXPECT_EQ(got.triangle.size(), first.size());
}

// Found by tools/fuzz.sh (proto_batch_fuzzer): a batch whose columns have
// different lengths (here x y z only, the normals then asked for) is also
// left as it was; each column goes back to its own length.
TEST(WireColumns, ALateBadColumnLeavesColumnsOfOtherLengthsAsTheyWere) {
  SampleFields fields;
  fields.uv = false;
  fields.normal = true;
  v1::SampleBatch bad;
  ToProto(EveryColumn(2, 4, true), fields, Stream(ColumnPrecision::kFloat64), &bad);
  bad.mutable_f64()->add_ny(1.0);  // 3 values for 2 samples
  SampleBatch got;
  got.index = {0};
  got.x = got.y = got.z = {0.5};
  const SampleBatch before = got;
  EXPECT_EQ(AppendFromProto(bad, fields, &got).code(), absl::StatusCode::kDataLoss);
  EXPECT_EQ(got.index, before.index);
  EXPECT_EQ(got.x, before.x);
  EXPECT_EQ(got.z, before.z);
  EXPECT_TRUE(got.nx.empty() && got.ny.empty() && got.u.empty());
}

TEST(WireColumns, ARequestLeavingNoValueColumnIsInvalidArgumentAndTheFlagsRoundTrip) {
  v1::SampleRequest request;
  request.set_count(10);
  request.set_omit_uv(true);
  request.set_omit_xyz(true);
  const auto refused = FromProto(request);
  EXPECT_EQ(refused.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(refused.status().message().find("no value column"), std::string::npos);
  request.set_density(true);
  const auto accepted = FromProto(request);
  ASSERT_TRUE(accepted.ok()) << accepted.status();
  EXPECT_FALSE(accepted->request.fields.uv || accepted->request.fields.xyz);
  const v1::SampleRequest back = ToProto(accepted->request, accepted->stream);
  EXPECT_TRUE(back.omit_uv() && back.omit_xyz() && back.density());
  request.set_omit_uv(false);
  EXPECT_TRUE(FromProto(request)->request.fields.uv);
}

TEST(StreamHeader, ReadsAsTheStreamInfoItCarries) {
  TreeSummary tree;
  tree.kind = "surface";
  tree.key = "0123456789abcdef";
  tree.leaves = 42;
  v1::StreamHeader header;
  ToProto(tree, header.mutable_tree());
  header.set_algorithm_version("sfcsampler-4");
  header.set_seed(9);
  header.set_begin(100);
  header.set_end(200);
  header.set_expected_samples(-1);
  const StreamInfo info = FromProto(header);
  EXPECT_EQ(info.tree.key, "0123456789abcdef");
  EXPECT_EQ(info.tree.leaves, 42u);
  EXPECT_EQ(info.algorithm_version, "sfcsampler-4");
  EXPECT_EQ(info.seed, 9u);
  EXPECT_EQ(info.begin, 100u);
  EXPECT_EQ(info.end, 200u);
  EXPECT_EQ(info.expected_samples, -1);
}

}  // namespace
}  // namespace sfc
