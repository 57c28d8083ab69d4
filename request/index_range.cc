#include "request/index_range.h"

#include "absl/strings/str_format.h"

namespace sfc {

absl::StatusOr<std::pair<uint64_t, uint64_t>> ResolveIndexRange(
    const SampleRequest& request) {
  const uint64_t n = request.count;
  if (request.shard_count > 0) {
    if (request.begin != 0 || request.end != 0) {
      return absl::InvalidArgumentError("ask for either an index range or a shard, not both");
    }
    if (request.shard_index >= request.shard_count) {
      return absl::InvalidArgumentError(
          absl::StrFormat("shard index %d must be below the shard count %d", request.shard_index,
                          request.shard_count));
    }
    // Shard i of K holds [floor(iN/K), floor((i+1)N/K)).
    auto bound = [&](uint64_t i) {
      return static_cast<uint64_t>(static_cast<unsigned __int128>(i) * n / request.shard_count);
    };
    return std::make_pair(bound(request.shard_index), bound(request.shard_index + 1));
  }
  const uint64_t end = request.end == 0 ? n : request.end;
  if (request.begin > end || end > n) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "the index range [%d, %d) is not inside the set of %d samples; it needs begin <= end <= "
        "count",
        request.begin, end, n));
  }
  return std::make_pair(request.begin, end);
}

}  // namespace sfc
