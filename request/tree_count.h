// How many samples a request's tree is sized for: the one rule every path
// that builds a tree for a request follows (the engine's Start, the server's
// model prepare, Python's and the CLI's prepare). Thread-safe, pure function.
#ifndef SFCSAMPLER_REQUEST_TREE_COUNT_H_
#define SFCSAMPLER_REQUEST_TREE_COUNT_H_

#include <cstdint>

#include "absl/status/statusor.h"
#include "request/sample_request.h"

namespace sfc {

// tree_count, or count when tree_count is 0. INVALID_ARGUMENT when
// tree_count is set below count: the tree must hold the whole set (a
// progressive set passes its final size each time it is extended).
absl::StatusOr<uint64_t> ResolveTreeCount(const SampleRequest& request);

}  // namespace sfc

#endif  // SFCSAMPLER_REQUEST_TREE_COUNT_H_
