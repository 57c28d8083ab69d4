// Meshes through the engine (issue 12): obj: and ply: specs sample the same
// mesh alike, whether the file is read in process or named by its hash; the
// triangle column and the barycentric u, v place every sample on its
// triangle; densities reach the mesh tree; bad specs and files are refused
// with the file named.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <string>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "engine/sampling_engine.h"
#include "gtest/gtest.h"
#include "kinds/registered_kinds.h"
#include "mesh/icosphere.h"
#include "mesh/mesh_loader.h"
#include "mesh/mesh_writer.h"
#include "tests/engine_helpers.h"

namespace sfc {
namespace {

// A model source that holds models by hash, as the server's store does.
class MemoryModels final : public ModelSource {
 public:
  std::string Add(ModelFormat format, std::string bytes) {
    StoredModel m;
    m.format = format;
    m.sha256 = Sha256Hex(bytes);
    m.bytes = std::make_shared<const std::string>(std::move(bytes));
    models_[m.sha256] = m;
    return m.Spec();
  }
  absl::StatusOr<StoredModel> Resolve(const ModelSpec& spec) const override {
    auto it = models_.find(spec.sha256);
    if (it == models_.end()) return absl::NotFoundError("no such model");
    return it->second;
  }

 private:
  std::map<std::string, StoredModel> models_;
};

SampleRequest MeshRequest(const std::string& surface, uint64_t count) {
  SampleRequest r;
  r.tree.surface = surface;
  r.count = count;
  r.seed = 7;
  r.fields.triangle = true;
  r.fields.normal = true;
  return r;
}

TEST(EngineMesh, AFileAndItsHashGiveTheSameSamplesOnTheirTriangles) {
  const TriangleMesh sphere = MakeIcosphere(3);
  const std::string ply = MeshToPly(sphere, /*binary=*/true);
  const std::string path = WriteTemp("engine_mesh_sphere.ply", ply);
  DirectTreeSource source;
  FileModelSource files;
  MemoryModels store;
  const std::string by_hash = store.Add(ModelFormat::kPly, ply);
  SamplingEngine local(RegisteredSurfaceKinds(), {}, &source, &files);
  SamplingEngine remote(RegisteredSurfaceKinds(), {}, &source, &store);

  const SampleBatch a = DrawAll(local, MeshRequest("ply:" + path, 5000));
  const SampleBatch b = DrawAll(remote, MeshRequest(by_hash, 5000));
  ASSERT_EQ(a.size(), 5000u);
  EXPECT_EQ(a.x, b.x);
  EXPECT_EQ(a.triangle, b.triangle);
  ASSERT_EQ(a.triangle.size(), a.size());
  for (size_t i = 0; i < a.size(); ++i) {
    ASSERT_LT(a.triangle[i], sphere.triangles.size());
    const double w = 1 - a.u[i] - a.v[i];
    ASSERT_GE(a.u[i], 0);
    ASSERT_GE(a.v[i], 0);
    ASSERT_GE(w, -1e-12);
    // The point is the triangle's barycentric combination.
    const auto& t = sphere.triangles[a.triangle[i]];
    const Vec3 p = sphere.positions[t[0]] * w + sphere.positions[t[1]] * a.u[i] +
                   sphere.positions[t[2]] * a.v[i];
    ASSERT_NEAR(p.x, a.x[i], 1e-12);
    ASSERT_NEAR(p.y, a.y[i], 1e-12);
    ASSERT_NEAR(p.z, a.z[i], 1e-12);
  }
}

TEST(EngineMesh, BlueSpreadsTheSamplesForAnyThreadCount) {
  // A unit icosphere: chord distances against the hexagonal spacing on its
  // own area (a little under 4 pi).
  const TriangleMesh sphere = MakeIcosphere(4);
  double area = 0;
  for (const auto& t : sphere.triangles) {
    const Vec3& a = sphere.positions[t[0]];
    area += Norm(Cross(sphere.positions[t[1]] - a, sphere.positions[t[2]] - a)) / 2;
  }
  const std::string path = WriteTemp("engine_mesh_blue.ply", MeshToPly(sphere, true));
  DirectTreeSource source;
  FileModelSource files;
  EngineLimits one, three;
  one.generation_threads = 1, three.generation_threads = 3;
  SamplingEngine a(RegisteredSurfaceKinds(), {one}, &source, &files);
  SamplingEngine b(RegisteredSurfaceKinds(), {three}, &source, &files);
  SampleRequest r = MeshRequest("ply:" + path, 4096);
  r.sequence = SequenceKind::kBlue;
  const SampleBatch x = DrawAll(a, r);
  const SampleBatch y = DrawAll(b, r);
  ASSERT_EQ(x.size(), 4096u);
  EXPECT_EQ(x.x, y.x);
  EXPECT_EQ(x.triangle, y.triangle);
  double nearest_min = 1e300, nearest_sum = 0;
  for (size_t i = 0; i < x.size(); ++i) {
    double nearest = 1e300;
    for (size_t j = 0; j < x.size(); ++j) {
      if (j == i) continue;
      const Vec3 d{x.x[i] - x.x[j], x.y[i] - x.y[j], x.z[i] - x.z[j]};
      nearest = std::min(nearest, Dot(d, d));
    }
    nearest_min = std::min(nearest_min, std::sqrt(nearest));
    nearest_sum += std::sqrt(nearest);
  }
  const double hex = std::sqrt(2 * area / (std::sqrt(3.0) * 4096));
  // Jittered: about 0.06 and 0.56.
  EXPECT_GE(nearest_min / hex, 0.72);
  EXPECT_GE(nearest_sum / 4096 / hex, 0.79);
}

TEST(EngineMesh, LargeBatchesOnTwoThreadsAreTheSameSamples) {
  const std::string path = WriteTemp("engine_mesh_threads.ply", MeshToPly(MakeIcosphere(3), true));
  DirectTreeSource source;
  FileModelSource files;
  EngineLimits one, two;
  one.generation_threads = 1, two.generation_threads = 2;
  SamplingEngine a(RegisteredSurfaceKinds(), {one}, &source, &files);
  SamplingEngine b(RegisteredSurfaceKinds(), {two}, &source, &files);
  SampleRequest r = MeshRequest("ply:" + path, 100000);
  r.tree.density = "mean:offset=0.1";
  r.fields.density = r.fields.curve_position = true;
  auto draw = [&](const SamplingEngine& engine, size_t batch) {
    auto job = engine.Start(r);
    EXPECT_TRUE(job.ok()) << job.status();
    SampleBatch all;
    while (job.ok()) {
      auto n = job->cursor->Next(batch, &all);
      EXPECT_TRUE(n.ok()) << n.status();
      if (!n.ok() || *n == 0) break;
    }
    return all;
  };
  const SampleBatch serial = draw(a, 30000), parallel = draw(b, 30000), small = draw(b, 1000);
  ASSERT_EQ(serial.size(), 100000u);
  for (const SampleBatch* other : {&parallel, &small}) {
    EXPECT_EQ(other->index, serial.index);
    EXPECT_EQ(other->x, serial.x);
    EXPECT_EQ(other->u, serial.u);
    EXPECT_EQ(other->density, serial.density);
    EXPECT_EQ(other->curve_position, serial.curve_position);
    EXPECT_EQ(other->triangle, serial.triangle);
  }
}

// One density vocabulary: gaussian:floor=F never means two things. On a mesh
// it is refused (sfcsampler-3 gave |K| + F there, and max(|K|, F) would change
// bytes under the same version); the additive rule is named gaussian:offset=F.
TEST(EngineMesh, AFloorIsRefusedAndAnOffsetIsAdded) {
  const std::string path = WriteTemp("engine_mesh_floor.ply", MeshToPly(MakeIcosphere(3), true));
  DirectTreeSource source;
  FileModelSource files;
  SamplingEngine engine(RegisteredSurfaceKinds(), {}, &source, &files);
  SampleRequest r = MeshRequest("ply:" + path, 2000);
  r.fields.density = true;
  const double f = 1000;
  for (const char* name : {"gaussian", "mean"}) {
    r.tree.density = absl::StrCat(name, ":floor=", f);
    const absl::Status refused = engine.Start(r).status();
    EXPECT_EQ(refused.code(), absl::StatusCode::kInvalidArgument) << refused;
    EXPECT_NE(refused.message().find(absl::StrCat(name, ":offset=")), std::string::npos) << refused;
    r.tree.density = absl::StrCat(name, ":offset=", f);
    const SampleBatch offset = DrawAll(engine, r);
    ASSERT_EQ(offset.size(), 2000u);
    for (size_t i = 0; i < offset.size(); ++i) {
      ASSERT_GT(offset.density[i], f) << name << " sample " << i;  // |K| + f, |K| > 0
    }
  }
}

TEST(EngineMesh, ADensityInXYZMovesSamplesWhereItIsLarger) {
  const std::string path = WriteTemp("engine_mesh_density.obj", MeshToObj(MakeIcosphere(3)));
  DirectTreeSource source;
  FileModelSource files;
  SamplingEngine engine(RegisteredSurfaceKinds(), {}, &source, &files);
  SampleRequest r = MeshRequest("obj:" + path, 20000);
  r.tree.density = "expr:1+3*(z>0)";
  const SampleBatch b = DrawAll(engine, r);
  size_t upper = 0;
  for (double z : b.z) upper += z > 0;
  // Mass 4 on the upper half against 1 on the lower: 80% above, up to the
  // triangles that straddle z = 0 and the jittering.
  EXPECT_NEAR(static_cast<double>(upper) / b.size(), 0.8, 0.03);
}

TEST(EngineMesh, BadMeshSpecsAndFilesAreRefusedWithTheFileNamed) {
  DirectTreeSource source;
  FileModelSource files;
  SamplingEngine engine(RegisteredSurfaceKinds(), {}, &source, &files);
  const std::string truncated = WriteTemp("engine_mesh_truncated.ply",
                                          MeshToPly(MakeIcosphere(1), true).substr(0, 300));
  auto status = engine.Start(MeshRequest("ply:" + truncated, 10)).status();
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument) << status;
  EXPECT_NE(status.message().find("engine_mesh_truncated.ply"), std::string::npos) << status;

  const std::string ok = WriteTemp("engine_mesh_ok.obj", MeshToObj(MakeIcosphere(1)));
  SampleRequest r = MeshRequest("obj:" + ok, 10);
  r.tree.density = "whitney";
  EXPECT_EQ(engine.Start(r).status().code(), absl::StatusCode::kInvalidArgument);
  r.tree.density = "expr:u+v";  // a mesh has no parameters u, v
  EXPECT_EQ(engine.Start(r).status().code(), absl::StatusCode::kInvalidArgument);
  r.tree.density = "vertex:quality";  // an OBJ has no vertex properties
  EXPECT_EQ(engine.Start(r).status().code(), absl::StatusCode::kInvalidArgument);
  r.tree.density = "uniform";
  r.fields.face = true;  // faces are CAD models'
  EXPECT_EQ(engine.Start(r).status().code(), absl::StatusCode::kInvalidArgument);

  SamplingEngine no_models(RegisteredSurfaceKinds(), {}, &source);
  EXPECT_EQ(no_models.Start(MeshRequest("obj:" + ok, 10)).status().code(),
            absl::StatusCode::kInvalidArgument);
}

// A mesh's size (core/area_estimator.h's CheckSize) is that of the vertices
// its triangles use: a stray vertex at 1e200 that no triangle uses changes no
// sample, in a PLY and an OBJ; a triangle that uses it makes the mesh too
// large, refused with what to scale.
TEST(EngineMesh, AFarVertexCountsForTheSizeOnlyWhenATriangleUsesIt) {
  DirectTreeSource source;
  FileModelSource files;
  SamplingEngine engine(RegisteredSurfaceKinds(), {}, &source, &files);
  const TriangleMesh sphere = MakeIcosphere(3);
  TriangleMesh stray = sphere;
  stray.positions.push_back({1e200, 0, 0});
  for (const bool obj : {false, true}) {
    SCOPED_TRACE(obj ? "obj" : "ply");
    auto spec = [&](const std::string& name, const TriangleMesh& mesh) {
      const std::string file = absl::StrCat(name, obj ? ".obj" : ".ply");
      return absl::StrCat(obj ? "obj:" : "ply:",
                          WriteTemp(file, obj ? MeshToObj(mesh) : MeshToPly(mesh, true)));
    };
    for (const SequenceKind sequence : {SequenceKind::kJittered, SequenceKind::kSobol}) {
      SampleRequest plain = MeshRequest(spec("engine_mesh_plain", sphere), 5000);
      SampleRequest with_stray = MeshRequest(spec("engine_mesh_stray", stray), 5000);
      plain.sequence = with_stray.sequence = sequence;
      const SampleBatch a = DrawAll(engine, plain);
      const SampleBatch b = DrawAll(engine, with_stray);
      ASSERT_EQ(b.size(), 5000u);
      EXPECT_EQ(b.x, a.x);
      EXPECT_EQ(b.y, a.y);
      EXPECT_EQ(b.z, a.z);
      EXPECT_EQ(b.triangle, a.triangle);
    }
    TriangleMesh far = stray;
    far.triangles.push_back({0, 1, static_cast<uint32_t>(stray.positions.size() - 1)});
    const absl::Status refused =
        engine.Start(MeshRequest(spec("engine_mesh_far", far), 10)).status();
    EXPECT_EQ(refused.code(), absl::StatusCode::kInvalidArgument) << refused;
    EXPECT_NE(refused.message().find("spans 1e+200 (its bounding box's diagonal)"),
              std::string::npos)
        << refused;
    EXPECT_NE(refused.message().find("scale it into that range"), std::string::npos) << refused;
  }
}

// A convex n-gon of circumradius 1 in one face line, plus a separate triangle
// of area 1/2 beside it. tinyobjloader keeps corner counts in an unsigned
// char: a 300-gon was read as a 44-gon and the triangle after it from
// misaligned corners (D2 of the hostile-client probe).
std::string PolygonAndTriangle(int n, bool ply) {
  std::string vertices;
  for (int i = 0; i < n; ++i) {
    const double a = 2 * M_PI * i / n;
    vertices +=
        absl::StrFormat(ply ? "%.17g %.17g 0\n" : "v %.17g %.17g 0\n", std::cos(a), std::sin(a));
  }
  vertices += ply ? "3 0 0\n4 0 0\n3 1 0\n" : "v 3 0 0\nv 4 0 0\nv 3 1 0\n";
  std::string polygon = ply ? absl::StrCat(n) : "f";
  for (int i = 0; i < n; ++i) absl::StrAppend(&polygon, " ", ply ? i : i + 1);
  if (!ply) return absl::StrFormat("%s%s\nf %d %d %d\n", vertices, polygon, n + 1, n + 2, n + 3);
  return absl::StrFormat(
      "ply\nformat ascii 1.0\nelement vertex %d\nproperty double x\nproperty double y\n"
      "property double z\nelement face 2\nproperty list ushort int vertex_indices\n"
      "end_header\n%s%s\n3 %d %d %d\n",
      n + 3, vertices, polygon, n, n + 1, n + 2);
}

TEST(EngineMesh, PolygonsOf256OrMoreCornersAreReadWhole) {
  DirectTreeSource source;
  FileModelSource files;
  SamplingEngine engine(RegisteredSurfaceKinds(), {}, &source, &files);
  for (const int n : {256, 300, 1000}) {
    SCOPED_TRACE(n);
    const double polygon_area = 0.5 * n * std::sin(2 * M_PI / n);
    for (const bool ply : {false, true}) {
      const std::string bytes = PolygonAndTriangle(n, ply);
      auto mesh = LoadMesh(bytes, ply ? "ngon.ply" : "ngon.obj");
      ASSERT_TRUE(mesh.ok()) << mesh.status();
      EXPECT_EQ(mesh->stats.faces, 2u);
      EXPECT_EQ(mesh->triangles.size(), static_cast<size_t>(n - 2 + 1));
      EXPECT_NEAR(mesh->stats.area, polygon_area + 0.5, 1e-12);
    }
    const std::string path =
        WriteTemp(absl::StrCat("engine_mesh_ngon", n, ".obj"), PolygonAndTriangle(n, false));
    const SampleBatch b = DrawAll(engine, MeshRequest("obj:" + path, 20000));
    ASSERT_EQ(b.size(), 20000u);
    size_t on_triangle = 0;
    for (size_t i = 0; i < b.size(); ++i) on_triangle += b.x[i] >= 3 && b.x[i] <= 4;
    // Jittered samples: the triangle's share is its area's within a few
    // samples of the strata the triangle's edges cut.
    EXPECT_NEAR(static_cast<double>(on_triangle) / b.size(), 0.5 / (polygon_area + 0.5), 0.005);
    // The polygon's samples fill its disc, not only its rim.
    size_t inner = 0;
    for (size_t i = 0; i < b.size(); ++i) inner += std::hypot(b.x[i], b.y[i]) < 0.5;
    EXPECT_NEAR(static_cast<double>(inner) / (b.size() - on_triangle), 0.25 * M_PI / polygon_area,
                0.01);
  }
}

// A density whose integral overflows double precision is refused on a mesh as
// on a formula surface (one message, CurveTree::CheckMassIsFinite); it used to
// put every sample on one point (D3 of the hostile-client probe).
TEST(EngineMesh, ADensityWhoseIntegralOverflowsIsRefused) {
  DirectTreeSource source;
  FileModelSource files;
  SamplingEngine engine(RegisteredSurfaceKinds(), {}, &source, &files);
  auto expect_refused = [&](const SampleRequest& r, const std::string& file) {
    const absl::Status refused = engine.Start(r).status();
    EXPECT_EQ(refused.code(), absl::StatusCode::kInvalidArgument) << refused;
    EXPECT_NE(refused.message().find("overflow double precision; scale it down"), std::string::npos)
        << refused;
    EXPECT_NE(refused.message().find(file), std::string::npos) << refused;
  };
  const std::string square = WriteTemp(
      "engine_mesh_overflow.obj", "v 0 0 0\nv 100 0 0\nv 100 100 0\nv 0 100 0\nf 1 2 3\nf 1 3 4\n");
  SampleRequest r = MeshRequest("obj:" + square, 1000);
  r.tree.density = "expr:1e306";  // 1e310 over the square
  expect_refused(r, "engine_mesh_overflow.obj");
  // A density a hundred times smaller integrates to 1e308: sampled, spread.
  r.tree.density = "expr:1e304";
  const SampleBatch spread = DrawAll(engine, r);
  ASSERT_EQ(spread.size(), 1000u);
  size_t right = 0;
  for (double x : spread.x) right += x > 50;
  EXPECT_NEAR(right, 500.0, 10.0);

  const std::string weighted =
      WriteTemp("engine_mesh_overflow.ply",
                "ply\nformat ascii 1.0\nelement vertex 4\nproperty double x\nproperty double y\n"
                "property double z\nproperty double weight\nelement face 2\n"
                "property list uchar int vertex_indices\nend_header\n0 0 0 1e300\n1e5 0 0 1e300\n"
                "1e5 1e5 0 1e300\n0 1e5 0 1e300\n3 0 1 2\n3 0 2 3\n");
  SampleRequest w = MeshRequest("ply:" + weighted, 1000);
  w.tree.density = "vertex:weight";
  expect_refused(w, "engine_mesh_overflow.ply");
}

TEST(EngineMesh, PerVertexWeightsFromAPlyPropertyShiftTheSamples) {
  TriangleMesh sphere = MakeIcosphere(3);
  sphere.weights.clear();
  for (const Vec3& p : sphere.positions) sphere.weights.push_back(p.x > 0 ? 4.0 : 1.0);
  const std::string path =
      WriteTemp("engine_mesh_weights.ply", MeshToPly(sphere, false, "quality"));
  DirectTreeSource source;
  FileModelSource files;
  SamplingEngine engine(RegisteredSurfaceKinds(), {}, &source, &files);
  SampleRequest r = MeshRequest("ply:" + path, 20000);
  r.tree.density = "vertex:quality";
  const SampleBatch b = DrawAll(engine, r);
  size_t right = 0;
  for (double x : b.x) right += x > 0;
  EXPECT_GT(static_cast<double>(right) / b.size(), 0.7);
  r.tree.density = "vertex:missing";
  EXPECT_EQ(engine.Start(r).status().code(), absl::StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace sfc
