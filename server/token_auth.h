// Bearer-token authentication of the sampler RPCs (docs/SERVICE.md, security).
//
// TokenAuthenticator compares a presented "authorization" value with
// "Bearer <token>" in constant time: both are hashed with SHA-256 and the
// digests compared with OpenSSL's CRYPTO_memcmp, so neither the position of
// the first wrong byte nor the length leaks through timing.
//
// TokenAuthProcessor plugs it into gRPC as an AuthMetadataProcessor, which
// runs before any handler. gRPC attaches processors only to secure (TLS)
// credentials; on a plaintext port the service calls the same authenticator
// itself. Health checks and reflection stay open for probes and tools: only
// methods of sfcsampler.v1.Sampler need the token.
//
// Thread-safety: immutable, thread-safe.
#ifndef SFCSAMPLER_SERVER_TOKEN_AUTH_H_
#define SFCSAMPLER_SERVER_TOKEN_AUTH_H_

#include <array>
#include <string>
#include <string_view>

#include "grpcpp/security/auth_metadata_processor.h"

namespace sfc {

class TokenAuthenticator {
 public:
  // REQUIRES: token is not empty.
  explicit TokenAuthenticator(std::string_view token);

  // True when `authorization` is exactly "Bearer <token>".
  bool Matches(std::string_view authorization) const;

  // True for the RPC paths that need the token ("/sfcsampler.v1.Sampler/...").
  static bool Guards(std::string_view method_path);

  // The error every refused call gets.
  static constexpr char kRefusal[] =
      "this server needs the header \"authorization: Bearer <token>\" (sfcsampler --token-file)";

 private:
  std::array<unsigned char, 32> expected_digest_;
};

class TokenAuthProcessor final : public grpc::AuthMetadataProcessor {
 public:
  explicit TokenAuthProcessor(std::string_view token) : authenticator_(token) {}
  // Cheap and non-blocking: run on the call's own thread.
  bool IsBlocking() const override { return false; }
  grpc::Status Process(const InputMetadata& auth_metadata, grpc::AuthContext* context,
                       OutputMetadata* consumed_auth_metadata,
                       OutputMetadata* response_metadata) override;

 private:
  const TokenAuthenticator authenticator_;
};

}  // namespace sfc

#endif  // SFCSAMPLER_SERVER_TOKEN_AUTH_H_
