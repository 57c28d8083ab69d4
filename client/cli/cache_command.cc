// `sfcsampler cache`: prints an sfcsampler-server's tree-cache statistics
// and limits (--server required; in process there is no cache).
#include <cstdio>
#include <memory>

#include "client/cli/commands.h"
#include "client/cli/connection_flags.h"
#include "client/cli/exit_status.h"

namespace sfc {

Command AddCacheCommand(CLI::App& app) {
  auto connection = std::make_shared<ConnectionFlags>();
  CLI::App* cache =
      app.add_subcommand("cache", "print the server's tree-cache statistics and limits");
  AddConnectionFlags(cache, connection.get(), ServerFlag::kRequired);
  return {cache, [connection] {
            auto client = ConnectClient(*connection);
            if (!client.ok()) return Fail(client.status());
            auto stats = (*client)->GetCacheStats();
            if (!stats.ok()) return Fail(stats.status());
            std::printf("%s", stats->DebugString().c_str());
            return 0;
          }};
}

}  // namespace sfc
