// What every RPC of the service shares: its clock, and the check a request
// hands the engine while its tree is built or waited for.
// Thread-safety: pure functions.
#ifndef SFCSAMPLER_SERVER_REQUEST_CONTROL_H_
#define SFCSAMPLER_SERVER_REQUEST_CONTROL_H_

#include <chrono>

#include "core/curve_tree.h"
#include "grpcpp/server_context.h"

namespace sfc {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start);

// A request's own check while its tree is built or waited for, or its blue
// set relaxed (it may be asked from several threads at once): the client
// is gone (CANCELLED), or the server's request deadline has passed
// (DEADLINE_EXCEEDED, saying what to do).
BuildControl RequestControl(const grpc::ServerContext* context, Clock::time_point deadline,
                            double deadline_seconds);

}  // namespace sfc

#endif  // SFCSAMPLER_SERVER_REQUEST_CONTROL_H_
