// libFuzzer target: a SampleRequest as the server receives it, wire bytes ->
// ParseFromString -> FromProto (proto/convert.h) -> the engine's checks and,
// when accepted, the whole job (fuzz/fuzz_job.h). Also checks that an
// accepted request survives ToProto -> FromProto unchanged, which the client
// library relies on when it resumes a stream.
#include <cstddef>
#include <cstdint>
#include <cstdio>

#include "fuzz/fuzz_job.h"
#include "proto/convert.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  sfc::v1::SampleRequest wire;
  if (!wire.ParseFromArray(data, static_cast<int>(size))) return 0;
  auto call = sfc::FromProto(wire);
  if (!call.ok()) {
    if (call.status().code() != absl::StatusCode::kInvalidArgument) {
      std::fprintf(stderr, "fuzz: FromProto: %s\n", call.status().ToString().c_str());
      __builtin_trap();
    }
    return 0;
  }
  const sfc::v1::SampleRequest sent = sfc::ToProto(call->request, call->stream);
  auto round_trip = sfc::FromProto(sent);
  if (!round_trip.ok() ||
      sfc::ToProto(round_trip->request, round_trip->stream).SerializeAsString() !=
          sent.SerializeAsString()) {
    std::fprintf(stderr, "fuzz: ToProto -> FromProto does not give the same request back\n");
    __builtin_trap();
  }
  sfc::fuzz::CheckRequest(call->request);
  return 0;
}
