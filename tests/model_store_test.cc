// Model specs and the server's content-addressed model store.
#include "server/model_store.h"

#include <fstream>

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
  EXPECT_EQ(store.Resolve(**ParseModelSpec(second.Spec())).status().code(), absl::StatusCode::kNotFound);
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
