// The flags that say which sfcsampler-server a subcommand asks: --server
// HOST:PORT and its credentials (optional where the subcommand can also run
// the sampler in process, required where it needs a server), and the client
// they open.
#ifndef SFCSAMPLER_CLIENT_CLI_CONNECTION_FLAGS_H_
#define SFCSAMPLER_CLIENT_CLI_CONNECTION_FLAGS_H_

#include <memory>
#include <string>

#include "CLI/CLI.hpp"
#include "absl/status/statusor.h"
#include "client/sampler_client.h"

namespace sfc {

struct ConnectionFlags {
  std::string server;      // host:port; "" = in process
  std::string token_file;  // bearer token
  bool tls = false;
  std::string tls_roots;
  std::string tls_cert, tls_key;  // client certificate for mutual TLS
};

// Whether a subcommand can run without a server (its samples then made in
// process) or needs one (the parser then refuses it without --server).
enum class ServerFlag { kOptional, kRequired };

// Adds --server, --token-file, --tls, --tls-roots, --tls-cert and --tls-key
// to `cmd`; `flags` must outlive parsing.
void AddConnectionFlags(CLI::App* cmd, ConnectionFlags* flags,
                        ServerFlag server = ServerFlag::kOptional);

// A client of the server `flags` names, with `options`' other fields (its
// target, TLS and token come from the flags; the token file is read now).
// REQUIRES: flags.server is not empty.
absl::StatusOr<std::unique_ptr<SamplerClient>> ConnectClient(const ConnectionFlags& flags,
                                                             ClientOptions options = {});

}  // namespace sfc

#endif  // SFCSAMPLER_CLIENT_CLI_CONNECTION_FLAGS_H_
