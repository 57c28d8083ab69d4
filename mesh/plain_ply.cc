#include "mesh/plain_ply.h"

#include <cstdint>
#include <cstring>
#include <vector>

#include "absl/strings/numbers.h"
#include "absl/strings/str_split.h"

namespace sfc {
namespace {

struct VertexProperty {
  std::string name;
  bool is_double;  // else float
  size_t offset;   // within a vertex record
};

// The value of vertex property `p` in the record at `record`.
double Value(const char* record, const VertexProperty& p) {
  if (p.is_double) {
    double d;
    std::memcpy(&d, record + p.offset, sizeof d);
    return d;
  }
  float f;
  std::memcpy(&f, record + p.offset, sizeof f);
  return static_cast<double>(f);
}

// The index of the property called `name`, or -1.
int Find(const std::vector<VertexProperty>& properties, absl::string_view name) {
  for (size_t k = 0; k < properties.size(); ++k) {
    if (properties[k].name == name) return static_cast<int>(k);
  }
  return -1;
}

}  // namespace

std::optional<TriangleMesh> ReadPlainBinaryPly(absl::string_view bytes, absl::string_view name,
                                               const std::string& weight_property) {
#if __BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__
  return std::nullopt;  // the values are copied as they lie
#endif
  constexpr size_t kMaxHeader = size_t{1} << 16;
  size_t pos = 0;
  auto next_line = [&](absl::string_view* line) {
    const size_t end = bytes.find('\n', pos);
    if (end == absl::string_view::npos || end > kMaxHeader) return false;
    *line = bytes.substr(pos, end - pos);
    pos = end + 1;
    return true;
  };
  absl::string_view line;
  if (!next_line(&line) || line != "ply") return std::nullopt;
  if (!next_line(&line) || line != "format binary_little_endian 1.0") return std::nullopt;

  enum class In { kNothing, kVertex, kFace } in = In::kNothing;
  uint64_t vertices = 0, faces = 0;
  bool seen_vertex = false, seen_face = false, face_list = false, unsigned_indices = false;
  std::vector<VertexProperty> properties;
  size_t stride = 0;
  while (true) {
    if (!next_line(&line)) return std::nullopt;
    if (line.find_first_of("\t\r\v\f") != absl::string_view::npos) return std::nullopt;
    const std::vector<absl::string_view> t = absl::StrSplit(line, ' ', absl::SkipEmpty());
    if (t.empty()) return std::nullopt;
    if (t[0] == "comment" || t[0] == "obj_info") continue;
    if (t[0] == "end_header" && t.size() == 1) break;
    if (t[0] == "element" && t.size() == 3) {
      uint64_t items;
      if (!absl::SimpleAtoi(t[2], &items) || items == 0) return std::nullopt;
      if (t[1] == "vertex" && !seen_vertex && !seen_face) {
        seen_vertex = true, vertices = items, in = In::kVertex;
      } else if (t[1] == "face" && seen_vertex && !seen_face) {
        seen_face = true, faces = items, in = In::kFace;
      } else {
        return std::nullopt;
      }
      continue;
    }
    if (t[0] != "property") return std::nullopt;
    if (in == In::kVertex && t.size() == 3) {
      const bool is_double = t[1] == "double" || t[1] == "float64";
      if (!is_double && t[1] != "float" && t[1] != "float32") return std::nullopt;
      if (Find(properties, t[2]) >= 0) return std::nullopt;  // a name given twice
      properties.push_back({std::string(t[2]), is_double, stride});
      stride += is_double ? 8 : 4;
      continue;
    }
    if (in == In::kFace && t.size() == 5 && !face_list && t[1] == "list" &&
        (t[2] == "uchar" || t[2] == "uint8") &&
        (t[4] == "vertex_indices" || t[4] == "vertex_index")) {
      if (t[3] == "uint" || t[3] == "uint32") {
        unsigned_indices = true;
      } else if (t[3] != "int" && t[3] != "int32") {
        return std::nullopt;
      }
      face_list = true;
      continue;
    }
    return std::nullopt;
  }
  if (!seen_face || !face_list) return std::nullopt;
  const int ix = Find(properties, "x"), iy = Find(properties, "y"), iz = Find(properties, "z");
  const int inx = Find(properties, "nx"), iny = Find(properties, "ny"),
            inz = Find(properties, "nz");
  const int iw = weight_property.empty() ? -1 : Find(properties, weight_property);
  if (ix < 0 || iy < 0 || iz < 0 || (!weight_property.empty() && iw < 0)) return std::nullopt;
  constexpr size_t kFaceBytes = 1 + 3 * 4;  // a count of 3 and three 32-bit indices
  const absl::string_view body = bytes.substr(pos);
  if (vertices > body.size() / stride || faces > body.size() / kFaceBytes ||
      vertices * stride + faces * kFaceBytes != body.size()) {
    return std::nullopt;
  }

  TriangleMesh mesh;
  mesh.name = std::string(name);
  mesh.positions.resize(vertices);
  const bool normals = inx >= 0 && iny >= 0 && inz >= 0;
  if (normals) mesh.normals.resize(vertices);
  if (iw >= 0) mesh.weights.resize(vertices);
  const char* record = body.data();
  for (uint64_t i = 0; i < vertices; ++i, record += stride) {
    mesh.positions[i] = {Value(record, properties[ix]), Value(record, properties[iy]),
                         Value(record, properties[iz])};
    if (normals) {
      mesh.normals[i] = {Value(record, properties[inx]), Value(record, properties[iny]),
                         Value(record, properties[inz])};
    }
    if (iw >= 0) mesh.weights[i] = Value(record, properties[iw]);
  }
  mesh.triangles.resize(faces);
  for (uint64_t f = 0; f < faces; ++f, record += kFaceBytes) {
    if (static_cast<uint8_t>(record[0]) != 3) return std::nullopt;  // a polygon
    for (int c = 0; c < 3; ++c) {
      uint32_t raw;
      std::memcpy(&raw, record + 1 + 4 * c, sizeof raw);
      // An int32 index below 0 is, as uint32, past any vertex count.
      const uint64_t index = unsigned_indices || static_cast<int32_t>(raw) >= 0 ? raw : UINT64_MAX;
      if (index >= vertices) return std::nullopt;
      mesh.triangles[f][c] = raw;
    }
  }
  mesh.stats.faces = faces;
  return mesh;
}

}  // namespace sfc
