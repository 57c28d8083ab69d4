// Hostile and damaged meshes (issue 21): face indices that would wrap in
// tinyobjloader's 32-bit parse, indices past the vertices, giant tokens, and
// face lines the reader would drop; every file is made here.
#include <string>

#include "absl/strings/str_cat.h"
#include "gtest/gtest.h"
#include "mesh/mesh_loader.h"

namespace sfc {
namespace {

constexpr char kFourVertices[] = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n";

absl::StatusOr<TriangleMesh> Obj(const std::string& text) {
  MeshLoadOptions options;
  options.format = ModelFormat::kObj;
  return LoadMesh(text, "hostile.obj", options);
}

void ExpectRefused(const absl::StatusOr<TriangleMesh>& mesh, const std::string& needle) {
  ASSERT_FALSE(mesh.ok()) << "loaded with " << mesh->triangles.size() << " triangles";
  EXPECT_EQ(mesh.status().code(), absl::StatusCode::kInvalidArgument) << mesh.status();
  EXPECT_NE(mesh.status().message().find(needle), std::string::npos) << mesh.status();
  EXPECT_NE(mesh.status().message().find("hostile"), std::string::npos) << mesh.status();
  EXPECT_LT(mesh.status().message().size(), 512u) << mesh.status();
}

TEST(MeshHostile, ObjIndicesThatWouldWrapAreRefusedQuoted) {
  for (const std::string token : {"4294967299", "99999999999999999999", "2147483648",
                                  "-2147483649", "5", "-5", "0"}) {
    ExpectRefused(Obj(absl::StrCat(kFourVertices, "f 1 2 ", token, "\n")),
                  absl::StrCat("'", token, "' is out of range"));
  }
  ExpectRefused(Obj(absl::StrCat(kFourVertices, "f 1 2 3x\n")), "'3x' is not an integer");
  // Indices count the vertices above the face line, as OBJ defines them.
  ExpectRefused(Obj("v 0 0 0\nv 1 0 0\nf 1 2 3\nv 0 1 0\n"), "defines 2 vertices");
  // Texture and normal indices too.
  ExpectRefused(Obj(absl::StrCat(kFourVertices, "vt 0 0\nf 1/1 2/4294967297 3/1\n")),
                "texture coordinate index '4294967297'");
  ExpectRefused(Obj(absl::StrCat(kFourVertices, "vn 0 0 1\nf 1//1 2//1 3//2\n")),
                "normal index '2'");
  // Good indices, backwards ones included, still load.
  auto mesh = Obj(absl::StrCat(kFourVertices, "f 1 2 3\nf -3 -1 -2\n"));
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  EXPECT_EQ(mesh->triangles.size(), 2u);
}

TEST(MeshHostile, GiantTokensAreClippedInMessages) {
  const std::string digits(100000, '7');
  ExpectRefused(Obj(absl::StrCat(kFourVertices, "f 1 2 ", digits, "\n")), "(100000 bytes)");
  ExpectRefused(Obj(absl::StrCat("v 0 0 ", std::string(100000, 'x'), "\n")), "(100000 bytes)");
  // The name too, with its control characters escaped.
  MeshLoadOptions options;
  options.format = ModelFormat::kObj;
  auto mesh = LoadMesh("v 0 0 0\n", absl::StrCat("a\nforged line", std::string(1 << 20, 'n')),
                       options);
  ASSERT_FALSE(mesh.ok());
  EXPECT_EQ(mesh.status().message().find('\n'), std::string::npos) << mesh.status();
  EXPECT_NE(mesh.status().message().find("a\\nforged"), std::string::npos) << mesh.status();
  EXPECT_LT(mesh.status().message().size(), 512u);
}

TEST(MeshHostile, ObjFaceLinesAreNotDroppedSilently) {
  ExpectRefused(Obj(absl::StrCat(kFourVertices, "f 1 2\n")), "three corners");
  ExpectRefused(Obj(absl::StrCat(kFourVertices, "f 1/1/1/1 2 3\n")), "more than three");
}

std::string AsciiPly(const std::string& face_list_type, const std::string& faces, int count) {
  return absl::StrCat("ply\nformat ascii 1.0\nelement vertex 4\nproperty double x\n"
                      "property double y\nproperty double z\nelement face ",
                      count, "\nproperty list uchar ", face_list_type,
                      " vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n", faces);
}

TEST(MeshHostile, PlyIndicesPastTheVerticesAreRefusedWithTheIndex) {
  MeshLoadOptions options;
  options.format = ModelFormat::kPly;
  auto good = LoadMesh(AsciiPly("int", "3 0 1 2\n3 1 3 2\n", 2), "hostile.ply", options);
  ASSERT_TRUE(good.ok()) << good.status();
  EXPECT_EQ(good->triangles.size(), 2u);
  for (const auto& [type, index] :
       {std::pair{"int", "4"}, std::pair{"int", "-1"}, std::pair{"uint", "4294967295"},
        std::pair{"int", "2147483647"}}) {
    auto mesh = LoadMesh(AsciiPly(type, absl::StrCat("3 0 1 ", index, "\n"), 1), "hostile.ply",
                         options);
    ExpectRefused(mesh, absl::StrCat("vertex index ", index, ","));
  }
}

// Issue 37: CGAL reads an ASCII 8-bit value as a short and casts it, and an
// unsigned one takes "-1" as its largest value; such values are refused,
// naming the property, the item and the type, never wrapped.
TEST(MeshHostile, AsciiPlyIntegersThatDoNotFitTheirTypeAreRefused) {
  MeshLoadOptions options;
  options.format = ModelFormat::kPly;
  // A uchar list count of 259 would be read as 3 (then 256 corners dropped).
  std::string corners = "259";
  for (int i = 0; i < 259; ++i) absl::StrAppend(&corners, " ", i % 4);
  ExpectRefused(LoadMesh(AsciiPly("int", corners + "\n", 1), "hostile.ply", options),
                "property 'vertex_indices' of face 0: 259 does not fit its type uchar (0..255)");
  // Corners of a narrow type, and a negative count.
  ExpectRefused(LoadMesh(AsciiPly("uchar", "3 0 1 300\n", 1), "hostile.ply", options),
                "300 does not fit its type uchar");
  ExpectRefused(LoadMesh(AsciiPly("ushort", "3 0 1 -1\n", 1), "hostile.ply", options),
                "-1 does not fit its type ushort (0..65535)");
  ExpectRefused(LoadMesh(AsciiPly("int", "-3 0 1 2\n", 1), "hostile.ply", options),
                "-3 does not fit its type uchar");
  // A uchar coordinate of 300 would be read as 44.
  const std::string uchar_vertex =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty uchar x\nproperty uchar y\n"
      "property uchar z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
  ExpectRefused(LoadMesh(uchar_vertex + "0 0 0\n300 0 0\n0 1 0\n3 0 1 2\n", "hostile.ply", options),
                "property 'x' of vertex 1: 300 does not fit its type uchar (0..255)");
  // The largest values of each type still load.
  auto mesh = LoadMesh(uchar_vertex + "0 0 0\n255 0 0\n0 255 0\n3 0 1 2\n", "hostile.ply", options);
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  EXPECT_EQ(mesh->positions[1].x, 255);
  mesh = LoadMesh(AsciiPly("uchar", "3 0 1 2\n", 1), "hostile.ply", options);
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  EXPECT_EQ(mesh->triangles.size(), 1u);
}

// Issue 37: tinyobjloader reads a hex float as 0; the line check refuses it.
TEST(MeshHostile, ObjHexFloatsAreRefused) {
  for (const std::string token : {"0x1p3", "0X10", "-0x1.8p1", "inf", "nan", "1e999"}) {
    ExpectRefused(Obj(absl::StrCat("v ", token, " 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")),
                  absl::StrCat("'", token, "' is not a finite decimal number"));
  }
  auto mesh = Obj("v 8 0 0\nv 1e0 0 +0.5\nv .5 1. -2E-1\nf 1 2 3\n");
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  EXPECT_EQ(mesh->positions[0].x, 8);
  EXPECT_EQ(mesh->positions[1].z, 0.5);
  EXPECT_EQ(mesh->positions[2].x, 0.5);
  EXPECT_EQ(mesh->positions[2].z, -0.2);
}

// A property line before any element line made CGAL's header parser write
// through a null pointer (fuzz/ply_fuzzer).
TEST(MeshHostile, PlyPropertyBeforeAnyElementIsRefused) {
  MeshLoadOptions options;
  options.format = ModelFormat::kPly;
  auto mesh =
      LoadMesh("ply\nformat ascii 1.0\nproperty double x\nelement vertex 1\nend_header\n0\n",
               "hostile.ply", options);
  ExpectRefused(mesh, "a property before any element");
  // Line 2 is the format line for CGAL, whatever it says.
  ExpectRefused(LoadMesh("ply\nelement ascii 1.0\nproperty double x\nend_header\n0\n",
                         "hostile.ply", options),
                "a property before any element");
  ExpectRefused(LoadMesh("ply\nformat ascii 1.0\nelement vertex 1\n", "hostile.ply", options),
                "end_header");
}

}  // namespace
}  // namespace sfc
