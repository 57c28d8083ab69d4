// Model specs and the server's content-addressed model store.
#include "server/model_store.h"

#include <fstream>
#include <optional>
#include <string>

#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace sfc {
namespace {

TEST(ModelSpec, NamesFormatAndReference) {
  auto path = *ParseModelSpec("step:parts/bracket.step");
  ASSERT_TRUE(path.has_value());
  EXPECT_EQ(path->format, ModelFormat::kStep);
  EXPECT_EQ(path->reference, "parts/bracket.step");
  EXPECT_EQ(path->sha256, "");
  const std::string hex(64, 'a');
  auto hashed = *ParseModelSpec(" obj:sha256=" + std::string(64, 'A') + " ");
  ASSERT_TRUE(hashed.has_value());
  EXPECT_EQ(hashed->sha256, hex);  // lower-cased
  EXPECT_FALSE(ParseModelSpec("sphere")->has_value());
  EXPECT_FALSE(ParseModelSpec("torus:R=2")->has_value());
  EXPECT_FALSE(ParseModelSpec("expr:x=u;y=v;z=0")->has_value());
  EXPECT_EQ(ParseModelSpec("ply:").status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(ParseModelSpec("ply:sha256=123").status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(ParseModelSpec("ply:sha256=" + std::string(64, 'g')).status().code(),
            absl::StatusCode::kInvalidArgument);
}

// Issue 37: an upload a proxy cut off (what gRPC reports for nginx's 413, in
// C++ and in Python) gets a sentence that names the proxy's limit; the
// server's own refusals get none.
TEST(ModelSpec, AnUploadCutByAProxyIsExplained) {
  for (const std::string message : {"Received RST_STREAM with error code 0",
                                    "Received http2 header with status: 413"}) {
    const std::string hint = UploadCutHint(message, 2800000);
    EXPECT_THAT(hint, ::testing::HasSubstr("2800000 bytes")) << message;
    EXPECT_THAT(hint, ::testing::HasSubstr("client_max_body_size")) << message;
  }
  EXPECT_EQ(UploadCutHint("upload \"a.obj\": 300000000 bytes, above the limit", 300000000), "");
  EXPECT_EQ(UploadCutHint("failed to connect to all addresses", 10), "");
}

TEST(Sha256Hex, MatchesTheStandardsTestVectors) {
  // FIPS 180-2, appendix B.1, and the empty message.
  EXPECT_EQ(Sha256Hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(Sha256Hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
}

TEST(ModelStore, KeysByContentAndStoresEachOnce) {
  ModelStore store(1 << 20, 1 << 16);
  bool already = true;
  auto a = store.Put(ModelFormat::kObj, "v 0 0 0\n", "a.obj", &already);
  ASSERT_TRUE(a.ok());
  EXPECT_FALSE(already);
  EXPECT_EQ(a->Spec(), "obj:sha256=" + Sha256Hex("v 0 0 0\n"));
  auto b = store.Put(ModelFormat::kObj, "v 0 0 0\n", "copy.obj", &already);
  EXPECT_TRUE(already);
  EXPECT_EQ(b->bytes, a->bytes);  // one copy
  EXPECT_EQ(store.stats().models, 1u);
  EXPECT_EQ(store.stats().uploads, 1u);
  auto found = store.Resolve(**ParseModelSpec(a->Spec()));
  ASSERT_TRUE(found.ok());
  EXPECT_EQ(*found->bytes, "v 0 0 0\n");
}

TEST(ModelStore, OpensNoPathsAndSaysWhatIsMissing) {
  ModelStore store(1 << 20, 1 << 16);
  EXPECT_EQ(store.Resolve(**ParseModelSpec("step:/etc/passwd")).status().code(),
            absl::StatusCode::kInvalidArgument);
  auto missing = store.Resolve(**ParseModelSpec("step:sha256=" + std::string(64, '0')));
  EXPECT_EQ(missing.status().code(), absl::StatusCode::kNotFound);
  EXPECT_NE(missing.status().message().find("upload it again"), std::string::npos);
}

TEST(ModelStore, TurnsAwayLargeModelsAndEvictsTheLeastRecentlyUsed) {
  ModelStore store(/*budget_bytes=*/300, /*max_model_bytes=*/200);
  EXPECT_EQ(store.Put(ModelFormat::kPly, std::string(201, 'x'), "big.ply").status().code(),
            absl::StatusCode::kResourceExhausted);
  EXPECT_EQ(store.stats().rejected, 1u);
  auto first = *store.Put(ModelFormat::kPly, std::string(150, 'a'), "a.ply");
  auto second = *store.Put(ModelFormat::kPly, std::string(100, 'b'), "b.ply");
  ASSERT_TRUE(store.Resolve(**ParseModelSpec(first.Spec())).ok());  // first is now recent
  auto third = *store.Put(ModelFormat::kPly, std::string(100, 'c'), "c.ply");
  EXPECT_TRUE(store.Resolve(**ParseModelSpec(first.Spec())).ok());
  EXPECT_EQ(store.Resolve(**ParseModelSpec(second.Spec())).status().code(),
            absl::StatusCode::kNotFound);
  EXPECT_TRUE(store.Resolve(**ParseModelSpec(third.Spec())).ok());
  EXPECT_EQ(store.stats().evictions, 1u);
  EXPECT_LE(store.stats().bytes, 300u);
  // An evicted model's bytes stay valid for whoever holds them.
  EXPECT_EQ(second.bytes->size(), 100u);
}

// An upload's string grows by doubling; the store keeps no more than the
// bytes it counts against its budget (the soak's model phase found up to 2x).
TEST(ModelStore, KeepsNoMoreThanTheBytesItCounts) {
  ModelStore store(/*budget_bytes=*/1 << 20, /*max_model_bytes=*/1 << 20);
  std::string upload;
  upload.reserve(1 << 19);
  upload.assign(1000, 'x');
  auto stored = store.Put(ModelFormat::kPly, std::move(upload), "grown.ply");
  ASSERT_TRUE(stored.ok()) << stored.status();
  EXPECT_EQ(store.stats().bytes, 1000u);
  EXPECT_LT(stored->bytes->capacity(), 2000u);
}

// Bytes being received count against the budget with the stored models, so
// uploads in flight cannot take the server past its budget.
TEST(ModelStore, UploadsBeingReceivedCountAgainstTheBudget) {
  ModelStore store(/*budget_bytes=*/300, /*max_model_bytes=*/300);
  auto stored = store.Put(ModelFormat::kPly, std::string(200, 's'), "stored.ply");
  ASSERT_TRUE(stored.ok()) << stored.status();
  std::optional<ModelStore::Upload> first(store.StartUpload());
  ASSERT_TRUE(first->Append(std::string(150, 'a')).ok());
  EXPECT_EQ(store.stats().upload_bytes, 150u);
  // 200 stored + 150 in flight would pass 300: the stored model made room.
  EXPECT_EQ(store.stats().evictions, 1u);
  EXPECT_EQ(store.stats().bytes, 0u);
  EXPECT_EQ(store.Resolve(**ParseModelSpec(stored->Spec())).status().code(),
            absl::StatusCode::kNotFound);

  ModelStore::Upload second = store.StartUpload();
  const absl::Status refused = second.Append(std::string(200, 'b'));
  EXPECT_EQ(refused.code(), absl::StatusCode::kResourceExhausted);
  EXPECT_THAT(std::string(refused.message()), ::testing::HasSubstr("retry"));
  EXPECT_EQ(store.stats().upload_bytes, 150u);

  first.reset();  // a client that leaves gives its bytes back
  EXPECT_EQ(store.stats().upload_bytes, 0u);
  // Chunks without a declared size are joined at the end, which needs the
  // bytes twice for a moment: 2 x 200 does not fit 300.
  ModelStore::Upload undeclared = store.StartUpload();
  ASSERT_TRUE(undeclared.Append(std::string(100, 'c')).ok());
  ASSERT_TRUE(undeclared.Append(std::string(100, 'c')).ok());
  EXPECT_EQ(store.Put(ModelFormat::kPly, std::move(undeclared), "c.ply").status().code(),
            absl::StatusCode::kResourceExhausted);
  EXPECT_EQ(store.stats().upload_bytes, 0u);
  // Declared up front, the same upload is counted once, at its first chunk,
  // and fits.
  ModelStore::Upload third = store.StartUpload();
  ASSERT_TRUE(third.Expect(200).ok());
  EXPECT_EQ(store.stats().upload_bytes, 0u);
  ASSERT_TRUE(third.Append(std::string(100, 'c')).ok());
  EXPECT_EQ(store.stats().upload_bytes, 200u);
  ASSERT_TRUE(third.Append(std::string(100, 'c')).ok());
  EXPECT_EQ(store.stats().upload_bytes, 200u);
  auto kept = store.Put(ModelFormat::kPly, std::move(third), "c.ply");
  ASSERT_TRUE(kept.ok()) << kept.status();
  EXPECT_EQ(kept->sha256, Sha256Hex(std::string(200, 'c')));
  EXPECT_EQ(*kept->bytes, std::string(200, 'c'));
  EXPECT_EQ(kept->bytes->capacity(), 200u);
  EXPECT_EQ(store.stats().upload_bytes, 0u);
  EXPECT_EQ(store.stats().bytes, 200u);
}

// A declared size is held once, from the first chunk, never twice: a model
// of 250 bytes fits a budget of 300 beside a stored one of 50, which stays.
// An upload that has declared its size but sent no chunk holds nothing; one
// whose declared size does not fit beside the others is turned away at its
// first chunk, saying what to do.
TEST(ModelStore, ADeclaredSizeIsHeldOnceFromTheFirstChunk) {
  ModelStore store(/*budget_bytes=*/300, /*max_model_bytes=*/300);
  auto stored = store.Put(ModelFormat::kObj, std::string(50, 's'), "s.obj");
  ASSERT_TRUE(stored.ok()) << stored.status();
  ModelStore::Upload upload = store.StartUpload();
  ASSERT_TRUE(upload.Expect(250).ok());
  EXPECT_EQ(store.stats().upload_bytes, 0u);
  ASSERT_TRUE(upload.Append(std::string(150, 'a')).ok());
  EXPECT_EQ(store.stats().upload_bytes, 250u);
  ASSERT_TRUE(upload.Append(std::string(100, 'a')).ok());
  EXPECT_EQ(store.stats().upload_bytes, 250u);
  auto kept = store.Put(ModelFormat::kObj, std::move(upload), "a.obj");
  ASSERT_TRUE(kept.ok()) << kept.status();
  EXPECT_EQ(*kept->bytes, std::string(250, 'a'));
  EXPECT_EQ(kept->bytes->capacity(), 250u);
  EXPECT_EQ(store.stats().upload_bytes, 0u);
  EXPECT_EQ(store.stats().bytes, 300u);
  EXPECT_EQ(store.stats().evictions, 0u);
  EXPECT_TRUE(store.Resolve(**ParseModelSpec(stored->Spec())).ok());

  ModelStore::Upload declared = store.StartUpload();
  ASSERT_TRUE(declared.Expect(200).ok());
  ModelStore::Upload silent = store.StartUpload();
  ASSERT_TRUE(silent.Expect(200).ok());
  EXPECT_EQ(store.stats().upload_bytes, 0u);
  EXPECT_EQ(store.stats().evictions, 0u);
  ASSERT_TRUE(declared.Append("v 0 0 0\n").ok());
  EXPECT_EQ(store.stats().upload_bytes, 200u);
  // 200 + 200 held would pass 300 whatever is evicted.
  const absl::Status refused = silent.Append("v 0 0 0\n");
  EXPECT_EQ(refused.code(), absl::StatusCode::kResourceExhausted);
  EXPECT_THAT(std::string(refused.message()), ::testing::HasSubstr("retry"));
  EXPECT_EQ(store.stats().upload_bytes, 200u);
  {
    ModelStore::Upload gone = std::move(declared);  // a client that leaves gives it back
  }
  EXPECT_EQ(store.stats().upload_bytes, 0u);
}

// An upload past max_model_bytes is refused at the chunk that passes it, or
// at once when it declares its size; a declared size must be kept to.
TEST(ModelStore, RefusesAnUploadAtTheChunkThatPassesTheLimit) {
  ModelStore store(/*budget_bytes=*/1000, /*max_model_bytes=*/250);
  ModelStore::Upload upload = store.StartUpload();
  ASSERT_TRUE(upload.Append(std::string(200, 'a')).ok());
  EXPECT_EQ(upload.Append(std::string(100, 'a')).code(), absl::StatusCode::kResourceExhausted);
  EXPECT_EQ(store.stats().rejected, 1u);
  EXPECT_EQ(upload.size(), 200u);
  EXPECT_EQ(store.StartUpload().Expect(251).code(), absl::StatusCode::kResourceExhausted);

  ModelStore::Upload more = store.StartUpload();
  ASSERT_TRUE(more.Expect(10).ok());
  EXPECT_EQ(more.Append(std::string(11, 'm')).code(), absl::StatusCode::kInvalidArgument);
  ModelStore::Upload fewer = store.StartUpload();
  ASSERT_TRUE(fewer.Expect(10).ok());
  ASSERT_TRUE(fewer.Append(std::string(9, 'f')).ok());
  EXPECT_EQ(store.Put(ModelFormat::kPly, std::move(fewer), "f.ply").status().code(),
            absl::StatusCode::kInvalidArgument);
}

TEST(FileModelSource, ReadsAndHashesAFile) {
  const std::string path = ::testing::TempDir() + "/model_source_test.obj";
  std::ofstream(path) << "v 1 2 3\n";
  FileModelSource files;
  auto model = files.Resolve(**ParseModelSpec("obj:" + path));
  ASSERT_TRUE(model.ok()) << model.status();
  EXPECT_EQ(model->sha256, Sha256Hex("v 1 2 3\n"));
  EXPECT_EQ(model->name, "model_source_test.obj");
  EXPECT_EQ(files.Resolve(**ParseModelSpec("obj:/no/such/file.obj")).status().code(),
            absl::StatusCode::kInvalidArgument);
  FileModelSource tiny(4);
  EXPECT_EQ(tiny.Resolve(**ParseModelSpec("obj:" + path)).status().code(),
            absl::StatusCode::kResourceExhausted);
}

}  // namespace
}  // namespace sfc
