// Loading OBJ and PLY meshes from bytes: round trips of the icosphere fixture
// through every format, named weight properties, polygons, degenerate and
// non-manifold input, and the errors for broken files.
#include "mesh/mesh_loader.h"

#include <unistd.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <tuple>

#include "absl/strings/str_format.h"
#include "gtest/gtest.h"
#include "mesh/icosphere.h"
#include "mesh/mesh_surface.h"
#include "mesh/mesh_writer.h"
#include "mesh/plain_ply.h"
#include "tests/mesh_test_util.h"

namespace sfc {
namespace {

using testing::ReadFile;
using testing::ScratchDir;
using testing::WriteFile;

// PLY keeps doubles bit for bit; tinyobjloader's own number parser can be
// off by an ulp or two from the 17 digits written, hence `tolerance` for OBJ.
void ExpectSameMesh(const TriangleMesh& a, const TriangleMesh& b, double tolerance = 0) {
  ASSERT_EQ(a.positions.size(), b.positions.size());
  ASSERT_EQ(a.triangles.size(), b.triangles.size());
  for (size_t i = 0; i < a.positions.size(); ++i) {
    if (tolerance == 0) {
      ASSERT_EQ(a.positions[i], b.positions[i]) << i;
    } else {
      ASSERT_LE(Norm(a.positions[i] - b.positions[i]), tolerance) << i;
    }
  }
  for (size_t t = 0; t < a.triangles.size(); ++t) ASSERT_EQ(a.triangles[t], b.triangles[t]) << t;
}

TEST(MeshLoader, IcosphereRoundTripsThroughObjAndBothPlyEncodings) {
  const TriangleMesh sphere = MakeIcosphere(6);
  ASSERT_EQ(sphere.triangles.size(), 81920u);
  const auto dir = ScratchDir("roundtrip");
  WriteFile(dir / "ico.obj", MeshToObj(sphere));
  WriteFile(dir / "ico_bin.ply", MeshToPly(sphere, /*binary=*/true));
  WriteFile(dir / "ico_ascii.ply", MeshToPly(sphere, /*binary=*/false));
  for (const char* file : {"ico.obj", "ico_bin.ply", "ico_ascii.ply"}) {
    SCOPED_TRACE(file);
    auto loaded = LoadMesh(ReadFile(dir / file), file);
    ASSERT_TRUE(loaded.ok()) << loaded.status();
    ExpectSameMesh(sphere, *loaded, std::string(file) == "ico.obj" ? 1e-15 : 0);
    EXPECT_EQ(loaded->stats.degenerate_triangles, 0u);
    CountEdges(&*loaded);
    EXPECT_EQ(loaded->stats.non_manifold_edges, 0u);
    EXPECT_EQ(loaded->stats.boundary_edges, 0u);  // closed surface
    EXPECT_NEAR(loaded->stats.area, 4 * M_PI, 0.01);
  }
  auto from_file = LoadMeshFile((dir / "ico.obj").string());
  ASSERT_TRUE(from_file.ok()) << from_file.status();
  ExpectSameMesh(sphere, *from_file, 1e-15);
}

TEST(MeshLoader, KeepsVertexNormalsAndNamedWeights) {
  TriangleMesh sphere = MakeIcosphere(2, /*with_normals=*/true);
  sphere.weights.resize(sphere.positions.size());
  for (size_t i = 0; i < sphere.weights.size(); ++i) sphere.weights[i] = 1 + sphere.positions[i].z;
  for (bool binary : {true, false}) {
    const std::string bytes = MeshToPly(sphere, binary, "importance");
    MeshLoadOptions options;
    options.weight_property = "importance";
    auto loaded = LoadMesh(bytes, "w.ply", options);
    ASSERT_TRUE(loaded.ok()) << loaded.status();
    ASSERT_EQ(loaded->weights.size(), sphere.weights.size());
    for (size_t i = 0; i < sphere.weights.size(); ++i)
      EXPECT_EQ(loaded->weights[i], sphere.weights[i]);
    ASSERT_EQ(loaded->normals.size(), sphere.positions.size());
    EXPECT_NEAR(loaded->normals[5].x, sphere.positions[5].x, 1e-12);
    options.weight_property = "missing";
    auto missing = LoadMesh(bytes, "w.ply", options);
    EXPECT_EQ(missing.status().code(), absl::StatusCode::kInvalidArgument);
    EXPECT_NE(missing.status().message().find("missing"), std::string::npos);
  }
  auto obj = LoadMesh(MeshToObj(sphere), "w.obj", {.weight_property = "importance"});
  EXPECT_EQ(obj.status().code(), absl::StatusCode::kInvalidArgument);
  auto obj_normals = LoadMesh(MeshToObj(sphere), "n.obj");
  ASSERT_TRUE(obj_normals.ok()) << obj_normals.status();
  EXPECT_EQ(obj_normals->normals.size(), sphere.positions.size());
}

TEST(MeshLoader, TriangulatesPolygonsAndCountsDegenerateAndNonManifold) {
  // A quad, a degenerate triangle (repeated corner), and three triangles on one edge.
  const std::string obj =
      "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 0 -1 0\n"
      "f 1 2 3 4\nf 1 2 2\nf 1 2 5\nf 1 6 2\n";
  auto mesh = LoadMesh(obj, "poly.obj");
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  EXPECT_EQ(mesh->stats.faces, 4u);
  EXPECT_EQ(mesh->stats.triangulated_polygons, 1u);
  EXPECT_EQ(mesh->triangles.size(), 5u);
  EXPECT_EQ(mesh->stats.degenerate_triangles, 1u);
  CountEdges(&*mesh);
  EXPECT_EQ(mesh->stats.non_manifold_edges, 1u);  // edge (1, 2): quad, the tent, the fin
  EXPECT_NEAR(mesh->stats.area, 1 + 0.5 + 0.5, 1e-15);
  const std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n";
  auto quad = LoadMesh(ply, "quad.ply");
  ASSERT_TRUE(quad.ok()) << quad.status();
  EXPECT_EQ(quad->triangles.size(), 2u);
  EXPECT_EQ(quad->stats.triangulated_polygons, 1u);
}

void ExpectError(const absl::StatusOr<TriangleMesh>& result, absl::StatusCode code,
                 const std::string& name, const std::string& words) {
  ASSERT_FALSE(result.ok()) << name;
  EXPECT_EQ(result.status().code(), code) << result.status();
  EXPECT_NE(result.status().message().find(name), std::string::npos) << result.status();
  EXPECT_NE(result.status().message().find(words), std::string::npos) << result.status();
}

// A field of /proc/self/status in bytes ("VmRSS", "VmHWM").
uint64_t StatusBytes(const std::string& field) {
  std::istringstream status(ReadFile("/proc/self/status"));
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind(field + ":", 0) == 0) return std::stoull(line.substr(field.size() + 1)) * 1024;
  }
  return 0;
}

// The files that cost the most memory a byte (MeshParseMemoryBytes): OBJ
// lines "f 1 2 3"; ASCII PLY faces of 100 one-digit corners; binary PLY faces
// of 255 uchar corners. About `size` bytes each.
std::string WorstObj(size_t size) {
  std::string bytes = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  while (bytes.size() < size) bytes += "f 1 2 3\n";
  return bytes;
}
std::string WorstPly(size_t size, bool binary) {
  std::string face = binary ? std::string(1, '\xff') : "100";
  for (int c = 0; c < (binary ? 255 : 100); ++c) {
    face += binary ? std::string(1, static_cast<char>(c % 3)) : absl::StrFormat(" %d", c % 3);
  }
  if (!binary) face += "\n";
  const size_t faces = size / face.size();
  std::string bytes = absl::StrFormat(
      "ply\nformat %s 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face %d\nproperty list uchar %s vertex_indices\nend_header\n",
      binary ? "binary_little_endian" : "ascii", faces, binary ? "uchar" : "int");
  if (binary) {
    const float corners[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    bytes.append(reinterpret_cast<const char*>(corners), sizeof(corners));
  } else {
    bytes += "0 0 0\n1 0 0\n0 1 0\n";
  }
  for (size_t f = 0; f < faces; ++f) bytes += face;
  return bytes;
}

// The memory a server reserves for a mesh parse covers the parse's peak on
// the files that make the most triangles of their bytes (a 64 MB OBJ of
// "f 1 2 3" lines once took 2.28 GB against a reservation of 8 bytes a byte).
// The peak is the growth of VmHWM, reset just before, over VmRSS then.
TEST(MeshLoader, ParseMemoryStaysWithinTheReservation) {
  if (ReadFile("/proc/self/status").empty()) GTEST_SKIP() << "no /proc/self/status";
  const size_t size = size_t{4} << 20;
  for (const auto& [format, name, bytes] :
       {std::tuple{ModelFormat::kObj, "worst.obj", WorstObj(size)},
        std::tuple{ModelFormat::kPly, "worst_ascii.ply", WorstPly(size, false)},
        std::tuple{ModelFormat::kPly, "worst_binary.ply", WorstPly(size, true)}}) {
    SCOPED_TRACE(name);
    if (!(std::ofstream("/proc/self/clear_refs") << "5")) GTEST_SKIP() << "no clear_refs";
    const uint64_t before = StatusBytes("VmRSS");
    {
      auto mesh = LoadMesh(bytes, name, {.format = format});
      ASSERT_TRUE(mesh.ok()) << mesh.status();
      ASSERT_GT(mesh->triangles.size(), bytes.size() / 9);
      const auto surface = MeshSurface::Create(*std::move(mesh), /*with_curvature=*/true);
    }
    const uint64_t peak = StatusBytes("VmHWM");
    const uint64_t growth = peak > before ? peak - before : 0;
    // Measured at 20-25 bytes a byte of OBJ and ASCII PLY, 40-50 of binary.
    EXPECT_GT(growth, 10 * bytes.size());
    EXPECT_LE(growth, MeshParseMemoryBytes(format, bytes))
        << static_cast<double>(growth) / bytes.size() << " bytes a byte";
  }
}

TEST(MeshLoader, BrokenFilesGetClearErrorsNamingTheFile) {
  const TriangleMesh sphere = MakeIcosphere(3);
  const auto dir = ScratchDir("broken");
  const std::string binary = MeshToPly(sphere, true);
  const std::string ascii = MeshToPly(sphere, false);
  const std::string obj = MeshToObj(sphere);
  WriteFile(dir / "cut_bin.ply", binary.substr(0, binary.size() * 2 / 3));
  WriteFile(dir / "cut_ascii.ply", ascii.substr(0, ascii.size() / 2));
  WriteFile(dir / "cut.obj", obj.substr(0, obj.size() / 3));  // only vertex lines remain
  WriteFile(dir / "cut_face.obj", obj.substr(0, obj.find("\nf ") + 6));  // "f a b" cut mid-line
  WriteFile(dir / "empty.ply", "");
  WriteFile(dir / "nan.obj", "v 0 0 0\nv 1 nan 0\nv 0 1 0\nf 1 2 3\n");
  WriteFile(dir / "short.obj", "v 0 0 0\nv 1 0 0\nv 0 1\nf 1 2 3\n");
  WriteFile(dir / "index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n");
  WriteFile(dir / "noface.ply",
            "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
            "property float z\nend_header\n0 0 0\n");
  WriteFile(dir / "inf.obj", "v 0 0 0\nv 1 1e999 0\nv 0 1 0\nf 1 2 3\n");
  WriteFile(dir / "nan_ascii.ply",
            "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
            "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
            "0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n");
  WriteFile(dir / "huge_count.ply",
            "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\n"
            "property float y\nproperty float z\nend_header\n");
  WriteFile(dir / "wide_list.ply",
            "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
            "property float z\nelement face 1\nproperty list int int vertex_indices\nend_header\n"
            "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  TriangleMesh nan_mesh = sphere;
  nan_mesh.positions[7].y = std::numeric_limits<double>::quiet_NaN();
  WriteFile(dir / "nan.ply", MeshToPly(nan_mesh, true));
  auto load = [&](const std::string& file) { return LoadMeshFile((dir / file).string()); };
  using absl::StatusCode;
  ExpectError(load("cut_bin.ply"), StatusCode::kInvalidArgument, "cut_bin.ply", "truncated");
  ExpectError(load("cut_ascii.ply"), StatusCode::kInvalidArgument, "cut_ascii.ply", "truncated");
  ExpectError(load("cut.obj"), StatusCode::kInvalidArgument, "cut.obj", "");
  ExpectError(load("cut_face.obj"), StatusCode::kInvalidArgument, "cut_face.obj", "truncated");
  ExpectError(load("empty.ply"), StatusCode::kInvalidArgument, "empty.ply", "empty");
  ExpectError(load("nan.obj"), StatusCode::kInvalidArgument, "nan.obj", "finite");
  ExpectError(load("short.obj"), StatusCode::kInvalidArgument, "short.obj", "three coordinates");
  ExpectError(load("index.obj"), StatusCode::kInvalidArgument, "index.obj", "vertex");
  ExpectError(load("noface.ply"), StatusCode::kInvalidArgument, "noface.ply", "no triangles");
  ExpectError(load("nan.ply"), StatusCode::kInvalidArgument, "nan.ply", "vertex 7");
  ExpectError(load("inf.obj"), StatusCode::kInvalidArgument, "inf.obj", "finite");
  ExpectError(load("nan_ascii.ply"), StatusCode::kInvalidArgument, "nan_ascii.ply", "vertex");
  ExpectError(load("huge_count.ply"), StatusCode::kInvalidArgument, "huge_count.ply", "truncated");
  ExpectError(load("wide_list.ply"), StatusCode::kInvalidArgument, "wide_list.ply",
              "list uchar int");
  ExpectError(LoadMesh(binary, "big.ply", {.max_bytes = binary.size() - 1}),
              StatusCode::kResourceExhausted, "big.ply", "limit");
  ExpectError(LoadMeshFile((dir / "cut_bin.ply").string(), {.max_bytes = 100}),
              StatusCode::kResourceExhausted, "cut_bin.ply", "limit");
  ExpectError(load("absent.obj"), StatusCode::kNotFound, "absent.obj", "");
  ExpectError(LoadMesh("v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n", "flat.obj"),
              StatusCode::kInvalidArgument, "flat.obj", "degenerate");
}

// Everything LoadMesh keeps of a mesh, compared exactly.
void ExpectIdentical(const TriangleMesh& a, const TriangleMesh& b) {
  ExpectSameMesh(a, b);
  ASSERT_EQ(a.normals.size(), b.normals.size());
  for (size_t i = 0; i < a.normals.size(); ++i) ASSERT_EQ(a.normals[i], b.normals[i]) << i;
  ASSERT_EQ(a.weights.size(), b.weights.size());
  for (size_t i = 0; i < a.weights.size(); ++i) ASSERT_EQ(a.weights[i], b.weights[i]) << i;
  EXPECT_EQ(a.stats.faces, b.stats.faces);
  EXPECT_EQ(a.stats.vertices, b.stats.vertices);
  EXPECT_EQ(a.stats.degenerate_triangles, b.stats.degenerate_triangles);
  EXPECT_EQ(a.stats.area, b.stats.area);
}

// The direct reader of plain binary PLY (mesh/plain_ply.h) takes the files it
// claims and makes the mesh CGAL's reader makes of the same values in ASCII
// (17 digits: exact); every other layout goes to CGAL's reader.
// A mesh whose triangles' areas overflow or underflow double precision is
// refused as too large or too small, not as "degenerate".
TEST(MeshLoader, AMeshBeyondDoublePrecisionIsRefusedWithWhatToScale) {
  for (const char* size : {"1e200", "1e-200"}) {
    const std::string obj =
        absl::StrFormat("v 0 0 0\nv %s 0 0\nv 0 %s 0\nf 1 2 3\n", size, size);
    auto loaded = LoadMesh(obj, "far.obj");
    ASSERT_EQ(loaded.status().code(), absl::StatusCode::kInvalidArgument) << size;
    EXPECT_NE(loaded.status().message().find("mesh 'far.obj' spans"), std::string::npos)
        << loaded.status();
  }
  EXPECT_TRUE(LoadMesh("v 0 0 0\nv 1e30 0 0\nv 0 1e30 0\nf 1 2 3\n", "wide.obj").ok());
}

TEST(MeshLoader, PlainBinaryPlyReadsAsTheGeneralReaderDoes) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> wobble(-0.2, 0.2);
  for (int trial = 0; trial < 12; ++trial) {
    SCOPED_TRACE(trial);
    TriangleMesh mesh = MakeIcosphere(1 + trial % 3, /*with_normals=*/trial % 2 == 0);
    for (Vec3& p : mesh.positions) p = p * (1 + wobble(rng));
    if (trial % 3 == 1) {
      mesh.weights.resize(mesh.positions.size());
      for (double& w : mesh.weights) w = 1 + wobble(rng);
    }
    const std::string weight = trial % 3 == 1 ? "weight" : "";
    const std::string binary = MeshToPly(mesh, /*binary=*/true, "weight");
    ASSERT_TRUE(ReadPlainBinaryPly(binary, "m.ply", weight).has_value());
    auto direct = LoadMesh(binary, "m.ply", {.weight_property = weight});
    auto general = LoadMesh(MeshToPly(mesh, /*binary=*/false, "weight"), "m.ply",
                            {.weight_property = weight});
    ASSERT_TRUE(direct.ok()) << direct.status();
    ASSERT_TRUE(general.ok()) << general.status();
    ExpectIdentical(*direct, *general);
  }

  // float vertex properties, uint indices and comment lines, by hand.
  const float xyz[4][3] = {{0, 0, 0}, {1.1f, 0, 0}, {0, 1.3f, 0}, {0, 0, 0.7f}};
  const uint32_t faces[2][3] = {{0, 1, 2}, {0, 2, 3}};
  std::string plain =
      "ply\nformat binary_little_endian 1.0\ncomment by hand\nelement vertex 4\n"
      "property float x\nproperty float y\nproperty float z\nelement face 2\n"
      "property list uchar uint vertex_indices\nend_header\n";
  std::string ascii =
      "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
      "property float z\nelement face 2\nproperty list uchar uint vertex_indices\nend_header\n";
  for (const auto& v : xyz) {
    plain.append(reinterpret_cast<const char*>(v), sizeof v);
    ascii += absl::StrFormat("%.9g %.9g %.9g\n", v[0], v[1], v[2]);
  }
  for (const auto& f : faces) {
    plain.push_back(3);
    plain.append(reinterpret_cast<const char*>(f), sizeof f);
    ascii += absl::StrFormat("3 %d %d %d\n", f[0], f[1], f[2]);
  }
  ASSERT_TRUE(ReadPlainBinaryPly(plain, "f.ply", "").has_value());
  auto direct = LoadMesh(plain, "f.ply"), general = LoadMesh(ascii, "f.ply");
  ASSERT_TRUE(direct.ok()) << direct.status();
  ASSERT_TRUE(general.ok()) << general.status();
  ExpectIdentical(*direct, *general);

  // Files the direct reader leaves to CGAL's: each still loads, or fails, as before.
  const std::string canonical = MeshToPly(MakeIcosphere(1), true);
  const size_t body = canonical.find("end_header\n") + 11;
  std::string quad = plain;  // the second face becomes a quad: one more index
  const size_t second_face = quad.size() - 13;
  quad[second_face] = 4;
  quad.insert(second_face + 13, std::string("\x01\x00\x00\x00", 4));
  std::string out_of_range = canonical;
  const uint32_t past = 1u << 20;
  std::memcpy(&out_of_range[canonical.size() - 4], &past, 4);
  std::string crlf = canonical;
  crlf.replace(crlf.find("end_header\n"), 11, "end_header\r\n");
  const std::string bodies[] = {canonical + "x", quad, out_of_range, crlf,
                                canonical.substr(0, body + 5)};
  for (const std::string& bytes : bodies) {
    EXPECT_FALSE(ReadPlainBinaryPly(bytes, "o.ply", "").has_value());
  }
  auto polygon = LoadMesh(quad, "quad.ply");
  ASSERT_TRUE(polygon.ok()) << polygon.status();
  EXPECT_EQ(polygon->stats.triangulated_polygons, 1u);
  EXPECT_EQ(polygon->triangles.size(), 3u);
  ExpectError(LoadMesh(out_of_range, "far.ply"), absl::StatusCode::kInvalidArgument, "far.ply",
              "vertex index 1048576");
  EXPECT_FALSE(ReadPlainBinaryPly(canonical, "w.ply", "importance").has_value());
  ExpectError(LoadMesh(canonical, "w.ply", {.weight_property = "importance"}),
              absl::StatusCode::kInvalidArgument, "w.ply", "importance");
}

}  // namespace
}  // namespace sfc
