// `sfcsampler health`: asks an sfcsampler-server's grpc.health.v1 service
// and prints SERVING (exit 0) or NOT_SERVING (exit 1); --server required.
#include <cstdio>
#include <memory>

#include "client/cli/commands.h"
#include "client/cli/connection_flags.h"
#include "client/cli/exit_status.h"

namespace sfc {

Command AddHealthCommand(CLI::App& app) {
  auto connection = std::make_shared<ConnectionFlags>();
  CLI::App* health = app.add_subcommand("health", "check the server's grpc.health.v1 status");
  AddConnectionFlags(health, connection.get(), ServerFlag::kRequired);
  return {health, [connection] {
            auto client = ConnectClient(*connection);
            if (!client.ok()) return Fail(client.status());
            auto serving = (*client)->CheckHealth();
            if (!serving.ok()) return Fail(serving.status());
            std::printf("%s\n", *serving ? "SERVING" : "NOT_SERVING");
            return *serving ? 0 : 1;
          }};
}

}  // namespace sfc
