#include "client/cli/connection_flags.h"

namespace sfc {

void AddConnectionFlags(CLI::App* cmd, ConnectionFlags* flags) {
  cmd->add_option("--server", flags->server,
                  "HOST:PORT of an sfcsampler-server (default: run in-process)");
  cmd->add_option("--token-file", flags->token_file, "file with the server's bearer token");
  cmd->add_flag("--tls", flags->tls, "connect with TLS (system roots)");
  cmd->add_option("--tls-roots", flags->tls_roots, "PEM roots to trust for TLS (implies --tls)");
  cmd->add_option("--tls-cert", flags->tls_cert,
                  "PEM client certificate for servers that require mutual TLS (implies --tls)");
  cmd->add_option("--tls-key", flags->tls_key, "PEM private key of --tls-cert");
}

}  // namespace sfc
