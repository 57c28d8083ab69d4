// Which samples of the set a request selects, before its region: indices
// [begin, end) (end 0 = count), or shard i of K, [floor(iN/K),
// floor((i+1)N/K)). Computed without the samples before them, so a client
// can resume or split a set on its own. Thread-safe, pure function.
#ifndef SFCSAMPLER_REQUEST_INDEX_RANGE_H_
#define SFCSAMPLER_REQUEST_INDEX_RANGE_H_

#include <cstdint>
#include <utility>

#include "absl/status/statusor.h"
#include "request/sample_request.h"

namespace sfc {

// INVALID_ARGUMENT for a range outside the set, a shard index not below the
// shard count, or both a range and a shard.
absl::StatusOr<std::pair<uint64_t, uint64_t>> ResolveIndexRange(const SampleRequest& request);

}  // namespace sfc

#endif  // SFCSAMPLER_REQUEST_INDEX_RANGE_H_
