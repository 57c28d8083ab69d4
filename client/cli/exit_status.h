// How a failed sfcsampler subcommand ends: the status on stderr as
// "sfcsampler: CODE: message", and the process exit code, 2 for
// INVALID_ARGUMENT (bad flags or input) and 1 for everything else.
#ifndef SFCSAMPLER_CLIENT_CLI_EXIT_STATUS_H_
#define SFCSAMPLER_CLIENT_CLI_EXIT_STATUS_H_

#include "absl/status/status.h"

namespace sfc {

// Prints `status` (not OK) and returns the exit code for it.
int Fail(const absl::Status& status);

}  // namespace sfc

#endif  // SFCSAMPLER_CLIENT_CLI_EXIT_STATUS_H_
