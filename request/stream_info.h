// What a Sample stream's header says about the set it carries, in the
// request library's types: the client library hands it to every batch
// callback (client/sampler_client.h); proto/convert.h reads it off the
// wire's StreamHeader, whose fields and names it has.
// Thread-safety: a plain value.
#ifndef SFCSAMPLER_REQUEST_STREAM_INFO_H_
#define SFCSAMPLER_REQUEST_STREAM_INFO_H_

#include <cstdint>
#include <string>

#include "request/tree_summary.h"

namespace sfc {

struct StreamInfo {
  TreeSummary tree;
  std::string algorithm_version;
  uint64_t seed = 0;
  uint64_t begin = 0, end = 0;    // the resolved index range
  int64_t expected_samples = -1;  // exact; -1 for a region request
};

}  // namespace sfc

#endif  // SFCSAMPLER_REQUEST_STREAM_INFO_H_
