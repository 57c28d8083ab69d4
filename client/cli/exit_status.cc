#include "client/cli/exit_status.h"

#include <cstdio>
#include <string>

namespace sfc {

int Fail(const absl::Status& status) {
  std::fprintf(stderr, "sfcsampler: %s: %s\n", absl::StatusCodeToString(status.code()).c_str(),
               std::string(status.message()).c_str());
  return status.code() == absl::StatusCode::kInvalidArgument ? 2 : 1;
}

}  // namespace sfc
