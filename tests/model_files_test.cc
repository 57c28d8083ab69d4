// request/model_files.h: the one table of model file extensions.
#include "request/model_files.h"

#include <set>
#include <string>

#include "gtest/gtest.h"

namespace sfc {
namespace {

TEST(ModelFiles, EveryExtensionNamesItsFormat) {
  std::set<ModelFormat> formats;
  for (const ModelExtension& e : ModelExtensions()) {
    ASSERT_EQ(e.extension.front(), '.');
    EXPECT_EQ(ModelFormatOfPath("dir/part" + std::string(e.extension)), e.format);
    formats.insert(e.format);
  }
  // Every model format has a file extension.
  for (const ModelFormat f : AllModelFormats()) {
    EXPECT_EQ(formats.count(f), 1u) << ModelFormatName(f);
  }
}

TEST(ModelFiles, EveryFormatIsNamedOnceAndListedForMessages) {
  const std::string list = ModelFormatList();
  for (const ModelFormat f : AllModelFormats()) {
    EXPECT_EQ(ModelFormatFromName(ModelFormatName(f)), f);
    EXPECT_NE(list.find(ModelFormatName(f)), std::string::npos) << list;
  }
  EXPECT_EQ(ModelFormatFromName("stl"), std::nullopt);
}

TEST(ModelFiles, ExtensionsIgnoreCaseAndOnlyTheLastCounts) {
  EXPECT_EQ(ModelFormatOfPath("PART.STP"), ModelFormat::kStep);
  EXPECT_EQ(ModelFormatOfPath("a/b.Igs"), ModelFormat::kIges);
  EXPECT_EQ(ModelFormatOfPath("scan.ply.gz"), std::nullopt);
  EXPECT_EQ(ModelFormatOfPath("notes.txt"), std::nullopt);
  EXPECT_EQ(ModelFormatOfPath("step"), std::nullopt);
  EXPECT_EQ(ModelFormatOfPath(".ply"), std::nullopt);  // a hidden file's name, no extension
}

TEST(ModelFiles, ListForMessages) {
  EXPECT_EQ(ModelExtensionList(), ".step .stp .iges .igs .nurbs .obj .ply");
}

}  // namespace
}  // namespace sfc
