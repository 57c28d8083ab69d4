// The bearer-token check: exact match only, whatever the length or prefix.
#include "server/token_auth.h"

#include "gtest/gtest.h"

namespace sfc {
namespace {

TEST(TokenAuthenticator, AcceptsExactlyTheBearerHeader) {
  const TokenAuthenticator auth("s3cret");
  EXPECT_TRUE(auth.Matches("Bearer s3cret"));
  for (const char* wrong : {"", "Bearer ", "Bearer s3cre", "Bearer s3cret ", "Bearer s3creT",
                            "bearer s3cret", "s3cret", "Bearer s3cret\n", "Bearer s3crets3cret"}) {
    EXPECT_FALSE(auth.Matches(wrong)) << '"' << wrong << '"';
  }
}

TEST(TokenAuthenticator, GuardsTheSamplerServiceOnly) {
  EXPECT_TRUE(TokenAuthenticator::Guards("/sfcsampler.v1.Sampler/Sample"));
  EXPECT_TRUE(TokenAuthenticator::Guards("/sfcsampler.v1.Sampler/GetCacheStats"));
  EXPECT_FALSE(TokenAuthenticator::Guards("/grpc.health.v1.Health/Check"));
  EXPECT_FALSE(
      TokenAuthenticator::Guards("/grpc.reflection.v1alpha.ServerReflection/ServerReflectionInfo"));
  EXPECT_FALSE(TokenAuthenticator::Guards("/sfcsampler.v1.SamplerX/Sample"));
}

TEST(TokenAuthProcessor, RefusesSamplerCallsWithoutTheTokenAndLetsHealthThrough) {
  TokenAuthProcessor processor("s3cret");
  grpc::AuthMetadataProcessor::OutputMetadata consumed, response;
  const std::string sample = "/sfcsampler.v1.Sampler/Sample",
                    health = "/grpc.health.v1.Health/Check";
  const std::string good = "Bearer s3cret", bad = "Bearer guess";
  grpc::AuthMetadataProcessor::InputMetadata md;
  md.emplace(":path", sample);
  EXPECT_EQ(processor.Process(md, nullptr, &consumed, &response).error_code(),
            grpc::StatusCode::UNAUTHENTICATED);
  md.emplace("authorization", bad);
  EXPECT_EQ(processor.Process(md, nullptr, &consumed, &response).error_code(),
            grpc::StatusCode::UNAUTHENTICATED);
  grpc::AuthMetadataProcessor::InputMetadata ok{{":path", sample}, {"authorization", good}};
  EXPECT_TRUE(processor.Process(ok, nullptr, &consumed, &response).ok());
  grpc::AuthMetadataProcessor::InputMetadata probe{{":path", health}};
  EXPECT_TRUE(processor.Process(probe, nullptr, &consumed, &response).ok());
  // No path: refuse rather than guess.
  grpc::AuthMetadataProcessor::InputMetadata unknown{};
  EXPECT_FALSE(processor.Process(unknown, nullptr, &consumed, &response).ok());
}

}  // namespace
}  // namespace sfc
