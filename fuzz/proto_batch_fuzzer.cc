// libFuzzer target: the client side of the wire, SampleResponse bytes ->
// ParseFromString -> AppendFromProto (proto/convert.h), for each combination
// of optional columns. A batch is either appended with every requested column
// as long as the index column, or refused with DATA_LOSS and nothing appended;
// a hostile or broken server must not make the client allocate more than its
// message holds.
#include <cstddef>
#include <cstdint>
#include <cstdio>

#include "proto/convert.h"

namespace {

[[noreturn]] void Fail(const char* what) {
  std::fprintf(stderr, "fuzz: %s\n", what);
  __builtin_trap();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  sfc::v1::SampleResponse response;
  if (!response.ParseFromArray(data, static_cast<int>(size))) return 0;
  for (int mask = 0; mask < 32; ++mask) {
    sfc::SampleFields fields;
    fields.normal = mask & 1;
    fields.density = mask & 2;
    fields.curve_position = mask & 4;
    fields.uv = !(mask & 8);
    fields.xyz = !(mask & 16);
    if (sfc::WireValueColumns(fields) == 0) continue;  // the server refuses such a request
    // A batch already holding one good sample (with the columns `fields`
    // keeps on the wire): a refused batch must leave it exactly so
    // (AppendFromProto takes back what it appended).
    sfc::SampleBatch batch;
    batch.index = {0};
    if (fields.uv) batch.u = batch.v = {0.5};
    if (fields.xyz) batch.x = batch.y = batch.z = {0.5};
    const sfc::SampleBatch before = batch;
    const absl::Status status = sfc::AppendFromProto(response.batch(), fields, &batch);
    if (!status.ok()) {
      if (status.code() != absl::StatusCode::kDataLoss || status.message().empty()) {
        Fail("a malformed batch is not DATA_LOSS with a message");
      }
      if (batch.index != before.index || batch.u != before.u || batch.v != before.v ||
          batch.x != before.x || batch.y != before.y || batch.z != before.z ||
          !batch.nx.empty() || !batch.ny.empty() || !batch.nz.empty() || !batch.density.empty() ||
          !batch.curve_position.empty() || !batch.face.empty() || !batch.triangle.empty()) {
        Fail("a refused batch left samples behind");
      }
      continue;
    }
    const size_t n = batch.size(), added = n - 1;
    const size_t uv = fields.uv ? n : 0, xyz = fields.xyz ? n : 0;
    if (batch.u.size() != uv || batch.v.size() != uv || batch.x.size() != xyz ||
        batch.y.size() != xyz || batch.z.size() != xyz) {
      Fail(
          "an accepted batch has a column of another length than its indices, or one not asked "
          "for");
    }
    if (fields.normal &&
        (batch.nx.size() != added || batch.ny.size() != added || batch.nz.size() != added)) {
      Fail("an accepted batch lacks a requested normal column");
    }
    if (fields.density && batch.density.size() != added) Fail("an accepted batch lacks densities");
    if (fields.curve_position && batch.curve_position.size() != added) {
      Fail("an accepted batch lacks curve positions");
    }
  }
  return 0;
}
