#include "server/request_control.h"

#include "absl/strings/str_format.h"

namespace sfc {

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

BuildControl RequestControl(const grpc::ServerContext* context, Clock::time_point deadline,
                            double deadline_seconds) {
  BuildControl control;
  control.check = [context, deadline, deadline_seconds]() -> absl::Status {
    if (context->IsCancelled()) {
      return absl::CancelledError("the client cancelled the request or its deadline passed");
    }
    if (Clock::now() > deadline) {
      return absl::DeadlineExceededError(absl::StrFormat(
          "the request was still being prepared (its tree built or its blue-noise set relaxed) "
          "when the server's request deadline of %g s passed; retry later (a tree build goes on "
          "while other requests wait for it) or ask for fewer samples",
          deadline_seconds));
    }
    return absl::OkStatus();
  };
  return control;
}

}  // namespace sfc
