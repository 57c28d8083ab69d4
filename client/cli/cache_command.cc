// `sfcsampler cache`: prints an sfcsampler-server's tree-cache statistics
// and limits (--server only; in process there is no cache).
#include <cstdio>
#include <memory>

#include "client/cli/commands.h"
#include "client/cli/connection_flags.h"
#include "client/cli/exit_status.h"
#include "client/cli/sample_source.h"

namespace sfc {

Command AddCacheCommand(CLI::App& app) {
  auto connection = std::make_shared<ConnectionFlags>();
  CLI::App* cache =
      app.add_subcommand("cache", "print the server's tree-cache statistics and limits");
  AddConnectionFlags(cache, connection.get());
  return {cache, [connection] {
            auto stats = OpenSampleSource(*connection)->CacheStats();
            if (!stats.ok()) return Fail(stats.status());
            std::printf("%s", stats->c_str());
            return 0;
          }};
}

}  // namespace sfc
