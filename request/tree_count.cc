#include "request/tree_count.h"

#include "absl/strings/str_format.h"

namespace sfc {

absl::StatusOr<uint64_t> ResolveTreeCount(const SampleRequest& request) {
  if (request.tree_count == 0) return request.count;
  if (request.tree_count < request.count) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "tree_count %d is below count %d: the tree must be sized for at least the whole set "
        "(leave tree_count 0 to size it for count, or set it to the final size of a progressive "
        "set)",
        request.tree_count, request.count));
  }
  return request.tree_count;
}

}  // namespace sfc
