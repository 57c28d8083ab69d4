// How a Sample stream's samples travel, beside the request that says which
// samples (request/sample_request.h): options for one call, kept apart from
// the request as LevelDB keeps ReadOptions apart from the key. The wire
// request is read once (proto/convert.h FromProto gives a SampleCall, both
// checked), and the stream options are passed down unchanged to what sizes
// the batches and encodes them; nobody below re-derives a default.
// Value types; thread-compatible.
#ifndef SFCSAMPLER_REQUEST_STREAM_OPTIONS_H_
#define SFCSAMPLER_REQUEST_STREAM_OPTIONS_H_

#include <cstdint>
#include <string_view>

#include "absl/status/statusor.h"
#include "request/sample_request.h"

namespace sfc {

// The width of the value columns (u v, x y z, normals, density,
// curve_position) on the wire and in output files: float64 is exact,
// float32 half the bytes.
enum class ColumnPrecision { kFloat64, kFloat32 };

// How value columns travel on the wire: packed repeated fields, or raw
// little-endian bytes (one memcpy a column at each end; the proto's
// RawColumns).
enum class ColumnEncoding { kPacked, kRaw };

// "float64" or "float32" (the CLI's --precision, Python's precision=);
// INVALID_ARGUMENT otherwise.
absl::StatusOr<ColumnPrecision> ParseColumnPrecision(std::string_view name);
// "raw" or "packed" (Python's encoding=); INVALID_ARGUMENT otherwise.
absl::StatusOr<ColumnEncoding> ParseColumnEncoding(std::string_view name);

// The samples a message carries when a request leaves the choice to the
// server (batch_size 0), unless fewer fit its max_message_bytes.
inline constexpr uint32_t kDefaultBatchSize = 65536;

struct StreamOptions {
  ColumnPrecision precision = ColumnPrecision::kFloat64;
  // Samples per message; 0 = the server chooses (kDefaultBatchSize, or as
  // many as fit its max_message_bytes when fewer).
  uint32_t batch_size = 0;
  // Packed is the wire's default: what clients that predate raw columns get.
  ColumnEncoding encoding = ColumnEncoding::kPacked;
};

// A Sample call as the server reads it: which samples, and how they travel.
struct SampleCall {
  SampleRequest request;
  StreamOptions stream;
};

}  // namespace sfc

#endif  // SFCSAMPLER_REQUEST_STREAM_OPTIONS_H_
