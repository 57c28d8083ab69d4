#include "client/cli/connection_flags.h"

#include <fstream>
#include <iterator>

#include "absl/strings/ascii.h"
#include "base/status_macros.h"

namespace sfc {
namespace {

// The bearer token in `path`, without trailing white space.
absl::StatusOr<std::string> ReadToken(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return absl::InvalidArgumentError("cannot read --token-file " + path);
  const std::string token((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return std::string(absl::StripTrailingAsciiWhitespace(token));
}

}  // namespace

void AddConnectionFlags(CLI::App* cmd, ConnectionFlags* flags, ServerFlag server) {
  if (server == ServerFlag::kRequired) {
    cmd->add_option("--server", flags->server,
                    "HOST:PORT of an sfcsampler-server (required: this command asks a server)")
        ->required();
  } else {
    cmd->add_option("--server", flags->server,
                    "HOST:PORT of an sfcsampler-server (default: run in-process)");
  }
  cmd->add_option("--token-file", flags->token_file, "file with the server's bearer token");
  cmd->add_flag("--tls", flags->tls, "connect with TLS (system roots)");
  cmd->add_option("--tls-roots", flags->tls_roots, "PEM roots to trust for TLS (implies --tls)");
  cmd->add_option("--tls-cert", flags->tls_cert,
                  "PEM client certificate for servers that require mutual TLS (implies --tls)");
  cmd->add_option("--tls-key", flags->tls_key, "PEM private key of --tls-cert");
}

absl::StatusOr<std::unique_ptr<SamplerClient>> ConnectClient(const ConnectionFlags& flags,
                                                             ClientOptions options) {
  options.target = flags.server;
  options.tls = flags.tls || !flags.tls_roots.empty() || !flags.tls_cert.empty();
  options.tls_root_certs_file = flags.tls_roots;
  options.tls_cert_file = flags.tls_cert;
  options.tls_key_file = flags.tls_key;
  if (!flags.token_file.empty()) {
    ASSIGN_OR_RETURN(options.token, ReadToken(flags.token_file));
  }
  return SamplerClient::Connect(options);
}

}  // namespace sfc
