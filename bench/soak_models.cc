#include "bench/soak_models.h"

#include <fstream>
#include <sstream>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#if SFC_SOAK_MODELS
#include "cad/fixtures.h"
#include "mesh/icosphere.h"
#include "mesh/mesh_writer.h"
#endif

namespace sfc {
#if SFC_SOAK_MODELS
namespace {

absl::StatusOr<std::string> ReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return absl::NotFoundError(absl::StrCat("cannot read ", path));
  std::ostringstream bytes;
  bytes << in.rdbuf();
  return bytes.str();
}

absl::Status WriteFile(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary);
  out << bytes;
  out.close();
  if (!out) return absl::InternalError(absl::StrCat("cannot write ", path));
  return absl::OkStatus();
}

// The format of a fixture file, from its extension.
std::string FormatOf(const std::string& path) { return path.substr(path.rfind('.') + 1); }

// `step` with its closed shell's face listed `copies` times: valid, small,
// and quadratic in OpenCASCADE's shell healing (tests/server_models_test.cc).
std::string ShellListingOneFace(const std::string& step, int copies) {
  std::string text = step;
  const size_t shell = text.find("CLOSED_SHELL('',(");
  if (shell == std::string::npos) return text;
  const size_t open = text.find('(', text.find(',', shell));
  const size_t close = text.find(')', open);
  const std::string face = text.substr(open + 1, close - open - 1);
  text.replace(open + 1, close - open - 1,
               absl::StrJoin(std::vector<std::string>(copies, face), ","));
  return text;
}

// `step` with one record nested `depth` parentheses deep (a reader that
// recursed per level would overflow its stack).
std::string DeeplyNested(const std::string& step, int depth) {
  std::string text = step;
  const size_t data = text.find("DATA;");
  if (data == std::string::npos) return text;
  const std::string record =
      absl::StrCat("\n#999999=DEEP(", std::string(depth, '('), std::string(depth, ')'), ");");
  text.insert(data + 5, record);
  return text;
}

}  // namespace

absl::StatusOr<SoakModels> SoakModels::Write(const std::string& dir, int large_subdivisions) {
  SoakModels models;
  auto cad_paths = cad::fixtures::WriteAll(dir);
  if (!cad_paths.ok()) return cad_paths.status();
  for (const std::string& path : *cad_paths) {
    auto bytes = ReadFile(path);
    if (!bytes.ok()) return bytes.status();
    const std::string format = FormatOf(path);
    models.good_.push_back({absl::StrCat(format, ":", path), format, bytes->size(), true});
    if (absl::EndsWith(path, "/sphere.step")) models.sphere_step_ = *bytes;
    if (absl::EndsWith(path, "/box_with_hole.step")) models.box_step_ = *bytes;
    if (absl::EndsWith(path, "/box_with_hole.iges")) models.box_iges_ = *bytes;
  }
  auto add_mesh = [&](std::vector<SoakModel>* list, int subdivisions, const std::string& kind) {
    const TriangleMesh mesh = MakeIcosphere(subdivisions, /*with_normals=*/subdivisions % 2 == 0);
    std::string bytes, format;
    if (kind == "obj") {
      bytes = MeshToObj(mesh), format = "obj";
    } else {
      bytes = MeshToPly(mesh, /*binary=*/kind == "ply"), format = "ply";
    }
    const std::string path = absl::StrCat(dir, "/icosphere", subdivisions, "_", kind, ".", format);
    if (absl::Status s = WriteFile(path, bytes); !s.ok()) return s;
    if (subdivisions == 3 && kind == "ply") models.small_ply_ = bytes;
    list->push_back({absl::StrCat(format, ":", path), format, bytes.size(), false});
    return absl::OkStatus();
  };
  for (int s = 1; s <= 6; ++s) {
    for (const char* kind : {"obj", "ply", "ascii_ply"}) {
      if (absl::Status status = add_mesh(&models.good_, s, kind); !status.ok()) return status;
    }
  }
  // Large meshes, each a parse of its own: the binary PLY at
  // `large_subdivisions` (8: 1.3 M triangles, 35 MB), and as text one
  // subdivision less (as text the finer one would pass 128 MiB).
  if (absl::Status s = add_mesh(&models.large_, large_subdivisions, "ply"); !s.ok()) return s;
  for (const char* kind : {"ply", "obj", "ascii_ply"}) {
    if (absl::Status s = add_mesh(&models.large_, large_subdivisions - 1, kind); !s.ok()) return s;
  }
  if (models.sphere_step_.empty() || models.box_step_.empty() || models.box_iges_.empty()) {
    return absl::InternalError("the CAD fixtures lack sphere.step or box_with_hole.step/.iges");
  }
  return models;
}

HostileUpload SoakModels::Hostile(std::mt19937_64& rng) const {
  // Every other upload of a kind repeats bytes the server has seen.
  const uint64_t variant = rng() % 2 == 0 ? 0 : rng() % 1000000;
  switch (rng() % 8) {
    case 0:
      return {"step", "deep.step", DeeplyNested(sphere_step_, 100000 + static_cast<int>(variant)),
              "STEP nested 100 000 deep"};
    case 1:
      // Rare: each costs the server's parse CPU budget (a few seconds).
      if (rng() % 4 == 0) {
        return {"step", "shell.step",
                ShellListingOneFace(sphere_step_, 60000 + static_cast<int>(variant % 1000)),
                "STEP shell listing one face 60 000 times"};
      }
      [[fallthrough]];
    case 2:
      return {"obj", "range.obj",
              absl::StrCat("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 ", 4 + variant, "\n"),
              "OBJ index past the vertices"};
    case 3:
      return {"ply", "billion.ply",
              absl::StrCat("ply\nformat binary_little_endian 1.0\nelement vertex ",
                           1000000000 + variant,
                           "\nproperty float x\nproperty float y\nproperty float z\n"
                           "element face 1\nproperty list uchar int vertex_indices\nend_header\n",
                           std::string(64, '\0')),
              "PLY declaring a billion vertices"};
    case 4:
      return {"step", "cut.step", box_step_.substr(0, 1000 + variant % 2000), "truncated STEP"};
    case 5:
      return {"iges", "cut.iges", box_iges_.substr(0, 2000 + 81 * (variant % 20)),
              "truncated IGES"};
    case 6:
      return {"ply", "cut.ply", small_ply_.substr(0, small_ply_.size() / 2 + variant % 1000),
              "truncated binary PLY"};
    default:
      return {"obj", "empty.obj", "", "empty upload"};
  }
}
#else   // a build without cad/ or mesh/
absl::StatusOr<SoakModels> SoakModels::Write(const std::string&, int) {
  return absl::UnimplementedError(
      "the model phase needs a build with cad/ and mesh/ (SFC_BUILD_CAD, SFC_BUILD_MESH)");
}
HostileUpload SoakModels::Hostile(std::mt19937_64&) const { return {}; }
#endif

}  // namespace sfc
