#include "python/bindings/mesh_arrays.h"

#include <cmath>
#include <cstring>

#include "absl/strings/str_format.h"

namespace sfc::python {
namespace {

template <typename Index>
bool WriteFaces(const Index* faces, size_t face_count, size_t vertex_count, char* out) {
  bool in_range = true;
  for (size_t f = 0; f < face_count; ++f, out += 13) {
    out[0] = 3;
    for (int k = 0; k < 3; ++k) {
      const Index i = faces[3 * f + k];
      in_range &= i >= 0 && static_cast<uint64_t>(i) < vertex_count;
      const int32_t narrow = static_cast<int32_t>(i);  // little-endian, as PLY's `int` here
      std::memcpy(out + 1 + 4 * k, &narrow, 4);
    }
  }
  return in_range;
}

}  // namespace

bool CanonicalPly(const double* vertices, size_t vertex_count, const double* normals,
                  const double* weights, const void* faces, bool wide_faces, size_t face_count,
                  std::string* out) {
  if (vertex_count < 3 || face_count == 0 || vertex_count - 1 > 0x7fffffff) return false;
  for (size_t i = 0; i < 3 * vertex_count; ++i) {
    if (!std::isfinite(vertices[i])) return false;
  }
  std::string header = absl::StrFormat(
      "ply\nformat binary_little_endian 1.0\nelement vertex %d\nproperty double x\nproperty "
      "double y\nproperty double z\n",
      vertex_count);
  if (normals != nullptr) header += "property double nx\nproperty double ny\nproperty double nz\n";
  if (weights != nullptr) absl::StrAppendFormat(&header, "property double %s\n", kWeightProperty);
  absl::StrAppendFormat(
      &header, "element face %d\nproperty list uchar int vertex_indices\nend_header\n", face_count);
  const size_t columns = 3 + (normals != nullptr ? 3 : 0) + (weights != nullptr ? 1 : 0);
  const size_t vertex_bytes = 8 * columns * vertex_count;
  out->resize(header.size() + vertex_bytes + 13 * face_count);
  char* p = out->data();
  std::memcpy(p, header.data(), header.size());
  char* vertex_out = p + header.size();
  if (columns == 3) {
    std::memcpy(vertex_out, vertices, vertex_bytes);  // x, y, z as float64 little-endian
  } else {
    char* q = vertex_out;
    for (size_t i = 0; i < vertex_count; ++i) {  // each vertex's record: x y z [nx ny nz] [w]
      std::memcpy(q, vertices + 3 * i, 24), q += 24;
      if (normals != nullptr) std::memcpy(q, normals + 3 * i, 24), q += 24;
      if (weights != nullptr) std::memcpy(q, weights + i, 8), q += 8;
    }
  }
  p = vertex_out + vertex_bytes;
  return wide_faces ? WriteFaces(static_cast<const int64_t*>(faces), face_count, vertex_count, p)
                    : WriteFaces(static_cast<const int32_t*>(faces), face_count, vertex_count, p);
}

}  // namespace sfc::python
