#include "mesh/mesh_writer.h"

#include <cstdint>
#include <cstring>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"

namespace sfc {
namespace {

template <typename T>
void AppendRaw(std::string* out, T value) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));  // little-endian hosts only (x86-64, arm64)
  out->append(bytes, sizeof(T));
}

}  // namespace

std::string MeshToObj(const TriangleMesh& mesh) {
  std::string out = "# sfcsampler mesh\n";
  for (const Vec3& p : mesh.positions)
    absl::StrAppendFormat(&out, "v %.17g %.17g %.17g\n", p.x, p.y, p.z);
  const bool normals = !mesh.normals.empty();
  if (normals) {
    for (const Vec3& n : mesh.normals)
      absl::StrAppendFormat(&out, "vn %.17g %.17g %.17g\n", n.x, n.y, n.z);
  }
  for (const auto& t : mesh.triangles) {
    if (normals) {
      absl::StrAppendFormat(&out, "f %d//%d %d//%d %d//%d\n", t[0] + 1, t[0] + 1, t[1] + 1,
                            t[1] + 1, t[2] + 1, t[2] + 1);
    } else {
      absl::StrAppendFormat(&out, "f %d %d %d\n", t[0] + 1, t[1] + 1, t[2] + 1);
    }
  }
  return out;
}

std::string MeshToPly(const TriangleMesh& mesh, bool binary, const std::string& weight_property) {
  const bool normals = !mesh.normals.empty();
  const bool weights = !mesh.weights.empty();
  std::string out = absl::StrCat("ply\nformat ", binary ? "binary_little_endian" : "ascii",
                                 " 1.0\ncomment sfcsampler mesh\nelement vertex ",
                                 mesh.positions.size(),
                                 "\nproperty double x\nproperty double y\nproperty double z\n");
  if (normals) out += "property double nx\nproperty double ny\nproperty double nz\n";
  if (weights) absl::StrAppend(&out, "property double ", weight_property, "\n");
  absl::StrAppend(&out, "element face ", mesh.triangles.size(),
                  "\nproperty list uchar int vertex_indices\nend_header\n");
  for (size_t i = 0; i < mesh.positions.size(); ++i) {
    const Vec3& p = mesh.positions[i];
    if (binary) {
      AppendRaw(&out, p.x), AppendRaw(&out, p.y), AppendRaw(&out, p.z);
      if (normals) {
        AppendRaw(&out, mesh.normals[i].x), AppendRaw(&out, mesh.normals[i].y),
            AppendRaw(&out, mesh.normals[i].z);
      }
      if (weights) AppendRaw(&out, mesh.weights[i]);
    } else {
      absl::StrAppendFormat(&out, "%.17g %.17g %.17g", p.x, p.y, p.z);
      if (normals) {
        absl::StrAppendFormat(&out, " %.17g %.17g %.17g", mesh.normals[i].x, mesh.normals[i].y,
                              mesh.normals[i].z);
      }
      if (weights) absl::StrAppendFormat(&out, " %.17g", mesh.weights[i]);
      out += '\n';
    }
  }
  for (const auto& t : mesh.triangles) {
    if (binary) {
      AppendRaw<uint8_t>(&out, 3);
      for (uint32_t c : t) AppendRaw<int32_t>(&out, static_cast<int32_t>(c));
    } else {
      absl::StrAppendFormat(&out, "3 %d %d %d\n", t[0], t[1], t[2]);
    }
  }
  return out;
}

}  // namespace sfc
