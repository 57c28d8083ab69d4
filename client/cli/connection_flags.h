// The flags that say where a subcommand's samples come from: --server
// HOST:PORT and its credentials, or nothing for the in-process sampler.
#ifndef SFCSAMPLER_CLIENT_CLI_CONNECTION_FLAGS_H_
#define SFCSAMPLER_CLIENT_CLI_CONNECTION_FLAGS_H_

#include <string>

#include "CLI/CLI.hpp"

namespace sfc {

struct ConnectionFlags {
  std::string server;      // host:port; "" = in process
  std::string token_file;  // bearer token
  bool tls = false;
  std::string tls_roots;
  std::string tls_cert, tls_key;  // client certificate for mutual TLS
};

// Adds --server, --token-file, --tls, --tls-roots, --tls-cert and --tls-key
// to `cmd`; `flags` must outlive parsing.
void AddConnectionFlags(CLI::App* cmd, ConnectionFlags* flags);

}  // namespace sfc

#endif  // SFCSAMPLER_CLIENT_CLI_CONNECTION_FLAGS_H_
