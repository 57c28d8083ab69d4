// Conversions between the sfcsampler.v1 wire types and the request library's
// types, shared by the server and the client library so both sides agree
// exactly, a tree's summary among them (what only a sampler has is in
// proto/service/service_convert.h).
// Also the one place that maps absl::Status to and from grpc::Status.
// Thread-safety: pure functions.
#ifndef SFCSAMPLER_PROTO_CONVERT_H_
#define SFCSAMPLER_PROTO_CONVERT_H_

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "core/types/sample_batch.h"
#include "grpcpp/support/status.h"
#include "request/sample_request.h"
#include "request/stream_info.h"
#include "request/stream_options.h"
#include "request/tree_summary.h"
#include "sfcsampler/v1/sampler.pb.h"

namespace sfc {

namespace v1 = ::sfcsampler::v1;

// INVALID_ARGUMENT for enum values this build does not know.
absl::StatusOr<TreeSpec> FromProto(const v1::TreeSpec& spec);
v1::TreeSpec ToProto(const TreeSpec& spec);
// The one reading of a Sample request: which samples and how they travel
// (precision, batch_size, column_encoding), so nothing reads those from the
// wire beside it. INVALID_ARGUMENT for enum values this build does not know
// and for a request that leaves no value column. ToProto(r, s) reads back
// as {r, s}.
absl::StatusOr<SampleCall> FromProto(const v1::SampleRequest& request);
v1::SampleRequest ToProto(const SampleRequest& request, const StreamOptions& stream = {});

// A tree's summary on the wire (TreeInfo) and back: the one mapping each
// way, so a summary reads the same in process and from a server. `out`
// should be clear. FromProto(ToProto(s)) == s.
void ToProto(const TreeSummary& summary, v1::TreeInfo* out);
TreeSummary FromProto(const v1::TreeInfo& tree);
// What a stream's header says (its tree through the mapping above; the
// echoed request is left out).
StreamInfo FromProto(const v1::StreamHeader& header);

// Fills `out` with `batch` in the stream's precision and column encoding
// (packed repeated fields, or little-endian bytes columns as the proto's
// RawColumns documents); its batch_size plays no part here. Consecutive
// indices are sent as first_index alone. `out` should be clear; its strings
// and arrays keep their capacity, so a message reused for the next batch
// allocates nothing.
void ToProto(const SampleBatch& batch, const SampleFields& fields, const StreamOptions& stream,
             v1::SampleBatch* out);
// The float columns a batch carries on the wire for `fields` (u v, x y z,
// normals, density, curve_position; SampleFields::uv and ::xyz leave the
// first two off).
size_t WireValueColumns(const SampleFields& fields);
// The largest number of samples one SampleResponse may carry so that it
// serialises to at most `max_message_bytes`, given the requested columns,
// precision, whether the batch lists its indices (regions and sequences not
// in index order do) and `reserved_bytes` for the stream header. 0 when not
// even one sample fits.
uint32_t MaxSamplesPerMessage(const SampleFields& fields, ColumnPrecision precision,
                              bool indices_listed, size_t reserved_bytes, size_t max_message_bytes);

// Appends the samples of `in` to `out`, whichever encoding and precision it
// uses (a raw column is one memcpy on little-endian hosts); columns `fields`
// does not ask for are ignored. DATA_LOSS when a column has the wrong length
// or a requested column is missing, and then nothing is appended;
// INVALID_ARGUMENT when `fields` leaves no value column.
absl::Status AppendFromProto(const v1::SampleBatch& in, const SampleFields& fields,
                             SampleBatch* out);

// The longest status message the server sends, in bytes; longer ones are
// clipped by ToGrpcStatus (base/echo.h ClipMessage).
inline constexpr size_t kMaxStatusMessageBytes = 1024;

// The one conversion of the server's statuses for the wire: same code, the
// message clipped to kMaxStatusMessageBytes.
grpc::Status ToGrpcStatus(const absl::Status& status);
absl::Status FromGrpcStatus(const grpc::Status& status);

}  // namespace sfc

#endif  // SFCSAMPLER_PROTO_CONVERT_H_
