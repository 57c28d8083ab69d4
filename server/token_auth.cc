#include "server/token_auth.h"

#include <openssl/crypto.h>
#include <openssl/sha.h>

namespace sfc {
namespace {

std::array<unsigned char, 32> Digest(std::string_view text) {
  std::array<unsigned char, 32> digest;
  SHA256(reinterpret_cast<const unsigned char*>(text.data()), text.size(), digest.data());
  return digest;
}

}  // namespace

TokenAuthenticator::TokenAuthenticator(std::string_view token)
    : expected_digest_(Digest("Bearer " + std::string(token))) {}

bool TokenAuthenticator::Matches(std::string_view authorization) const {
  const auto presented = Digest(authorization);
  return CRYPTO_memcmp(presented.data(), expected_digest_.data(), presented.size()) == 0;
}

bool TokenAuthenticator::Guards(std::string_view method_path) {
  constexpr std::string_view kGuarded = "/sfcsampler.v1.Sampler/";
  return method_path.substr(0, kGuarded.size()) == kGuarded;
}

grpc::Status TokenAuthProcessor::Process(const InputMetadata& auth_metadata, grpc::AuthContext*,
                                         OutputMetadata*, OutputMetadata*) {
  auto path = auth_metadata.find(":path");
  // Without a path we cannot tell what is called: refuse rather than guess.
  if (path != auth_metadata.end() &&
      !TokenAuthenticator::Guards(std::string_view(path->second.data(), path->second.size()))) {
    return grpc::Status::OK;
  }
  auto header = auth_metadata.find("authorization");
  if (header != auth_metadata.end() &&
      authenticator_.Matches(std::string_view(header->second.data(), header->second.size()))) {
    return grpc::Status::OK;
  }
  return grpc::Status(grpc::StatusCode::UNAUTHENTICATED, TokenAuthenticator::kRefusal);
}

}  // namespace sfc
