#include "mesh/mesh_loader.h"

#include <CGAL/IO/PLY/PLY_reader.h>
#include <tiny_obj_loader.h>

#include <cmath>
#include <cstdint>
#include <fstream>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "absl/algorithm/container.h"
#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_split.h"
#include "absl/strings/strip.h"
#include "base/echo.h"
#include "base/status_macros.h"
#include "mesh/plain_ply.h"
#include "request/model_files.h"

namespace sfc {
namespace {

using CgalPlyReader = CGAL::IO::internal::PLY_reader;
using CgalPlyElement = CGAL::IO::internal::PLY_element;
using CgalPlyNumber = CGAL::IO::internal::PLY_read_number;

absl::Status Malformed(absl::string_view name, absl::string_view what) {
  return absl::InvalidArgumentError(absl::StrFormat("mesh '%s': %s", name, what));
}

// Appends a polygon as a fan of triangles (0, i, i+1).
void AddPolygon(const std::vector<uint32_t>& corners, TriangleMesh* mesh) {
  ++mesh->stats.faces;
  if (corners.size() > 3) ++mesh->stats.triangulated_polygons;
  for (size_t i = 1; i + 1 < corners.size(); ++i) {
    mesh->triangles.push_back({corners[0], corners[i], corners[i + 1]});
  }
}

// ---------------------------------------------------------------- OBJ

// A face line of 256 or more corners: tinyobjloader keeps each face's corner
// count in an unsigned char (mesh_t::num_face_vertices), so the line scan
// keeps the true count of these few.
struct LongObjFace {
  uint64_t ordinal = 0;  // the face's place among the file's faces, from 0
  uint64_t corners = 0;
  size_t line_number = 0;
};

// What the line scan of an OBJ file found: its face lines, which the mesh
// must all hold afterwards (nothing dropped silently), and the long ones.
struct ObjCensus {
  uint64_t face_lines = 0;
  std::vector<LongObjFace> long_faces;  // by ordinal
};

// One corner's index of kind `what` ("vertex", "texture coordinate",
// "normal"): OBJ counts from 1, or backwards from -1 over the `defined`
// elements of that kind above the line. tinyobjloader parses indices into an
// int without checking for overflow, so 4294967299 would wrap to 3; here
// every index is read exactly (64-bit, overflow refused) and range-checked.
absl::Status CheckObjIndex(absl::string_view token, uint64_t defined, absl::string_view what,
                           absl::string_view plural, size_t line_number, absl::string_view name) {
  int64_t index = 0;
  const absl::string_view digits = absl::StartsWith(token, "-") ? token.substr(1) : token;
  const bool integer = !digits.empty() && absl::c_all_of(digits, absl::ascii_isdigit);
  if (integer && !absl::SimpleAtoi(token, &index)) index = 0;  // past 64 bits: out of range
  const bool in_range = integer && index != 0 &&
                        (index > 0 ? static_cast<uint64_t>(index) <= defined
                                   : static_cast<uint64_t>(-(index + 1)) < defined);
  if (in_range) return absl::OkStatus();
  return Malformed(
      name, absl::StrFormat("line %d: face %s index '%s' is %s; the file defines %d %s above "
                            "this line (indices 1..%d, or -1..-%d counting back)",
                            line_number, what, Echo(token),
                            integer ? "out of range" : "not an integer", defined, plural, defined,
                            defined));
}

// tinyobjloader reads a coordinate it cannot parse ("nan", a cut-off line) as
// 0 without a word, and wraps face indices past 32 bits, so the vertex and
// face lines are checked here first: a vertex has at least three numbers,
// each finite; a face has at least three corners, each index in range.
absl::StatusOr<ObjCensus> CheckObjLines(absl::string_view text, absl::string_view name) {
  ObjCensus census;
  uint64_t vertices = 0, texcoords = 0, normals = 0;
  size_t line_number = 0;
  for (absl::string_view line : absl::StrSplit(text, '\n')) {
    ++line_number;
    line = absl::StripAsciiWhitespace(line);
    const bool v = absl::StartsWith(line, "v ") || absl::StartsWith(line, "v\t");
    const bool f = absl::StartsWith(line, "f ") || absl::StartsWith(line, "f\t");
    if (absl::StartsWith(line, "vt ") || absl::StartsWith(line, "vt\t")) ++texcoords;
    if (absl::StartsWith(line, "vn ") || absl::StartsWith(line, "vn\t")) ++normals;
    if (!v && !f) continue;
    // A comment ends the line's data.
    if (const size_t hash = line.find('#'); hash != absl::string_view::npos) {
      line = line.substr(0, hash);
    }
    std::vector<absl::string_view> tokens =
        absl::StrSplit(line.substr(2), absl::ByAnyChar(" \t\r"), absl::SkipEmpty());
    if (f) {
      if (tokens.size() > std::numeric_limits<unsigned char>::max()) {
        census.long_faces.push_back({census.face_lines, tokens.size(), line_number});
      }
      ++census.face_lines;
      if (tokens.size() < 3) {
        return Malformed(name, absl::StrFormat("line %d: a face needs three corners, found %d "
                                               "(a truncated file?)",
                                               line_number, tokens.size()));
      }
      for (absl::string_view corner : tokens) {
        // v, v/vt, v/vt/vn or v//vn.
        std::vector<absl::string_view> parts = absl::StrSplit(corner, '/');
        if (parts.size() > 3) {
          return Malformed(name, absl::StrFormat("line %d: face corner '%s' has more than three "
                                                 "indices (v/vt/vn)",
                                                 line_number, Echo(corner)));
        }
        RETURN_IF_ERROR(CheckObjIndex(parts[0], vertices, "vertex", "vertices", line_number, name));
        if (parts.size() > 1 && !parts[1].empty()) {
          RETURN_IF_ERROR(
              CheckObjIndex(parts[1], texcoords, "texture coordinate", "texture coordinates",
                            line_number, name));
        }
        if (parts.size() > 2) {
          RETURN_IF_ERROR(CheckObjIndex(parts[2], normals, "normal", "normals", line_number, name));
        }
      }
      continue;
    }
    ++vertices;
    if (tokens.size() < 3) {
      return Malformed(name, absl::StrFormat("line %d: a vertex needs three coordinates, found %d "
                                             "(a truncated file?)",
                                             line_number, tokens.size()));
    }
    for (int c = 0; c < 3; ++c) {
      // Decimal only: SimpleAtod takes hex floats (0x1p3), which
      // tinyobjloader reads as 0.
      double value;
      if (tokens[c].find_first_not_of("0123456789+-.eE") != absl::string_view::npos ||
          !absl::SimpleAtod(tokens[c], &value) || !std::isfinite(value)) {
        return Malformed(name, absl::StrFormat("line %d: vertex coordinate '%s' is not a finite "
                                               "decimal number",
                                               line_number, Echo(tokens[c])));
      }
    }
  }
  return census;
}

absl::StatusOr<TriangleMesh> LoadObj(absl::string_view bytes, absl::string_view name,
                                     const MeshLoadOptions& options) {
  if (!options.weight_property.empty()) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "mesh '%s': OBJ files have no named vertex properties, so weight property '%s' cannot "
        "be read; give the mesh as PLY with a vertex property of that name",
        name, Echo(options.weight_property)));
  }
  ASSIGN_OR_RETURN(const ObjCensus census, CheckObjLines(bytes, name));
  tinyobj::ObjReader reader;
  tinyobj::ObjReaderConfig config;
  config.triangulate = false;  // we fan-triangulate and count the polygons
  config.vertex_color = false;
  const bool parsed = reader.ParseFromString(std::string(bytes), "", config);
  if (options.check) RETURN_IF_ERROR(options.check());
  if (!parsed) {
    return Malformed(name, absl::StrFormat("not a valid OBJ file: %s",
                                           Echo(absl::StripAsciiWhitespace(reader.Error()), 200)));
  }
  const std::string& warning = reader.Warning();
  if (absl::StrContains(warning, "out of bounds")) {
    return Malformed(name, "a face uses a vertex index past the vertices (a truncated file?)");
  }
  if (absl::StrContains(warning, "Degenerated face")) {
    return Malformed(name, "a face has fewer than three corners (a truncated file?)");
  }
  const tinyobj::attrib_t& attrib = reader.GetAttrib();
  uint64_t faces_read = 0;
  for (const tinyobj::shape_t& shape : reader.GetShapes()) {
    faces_read += shape.mesh.num_face_vertices.size();
  }
  if (faces_read != census.face_lines) {
    return Malformed(name,
                     absl::StrFormat("the file has %d face lines but the OBJ reader kept %d; "
                                     "a damaged face line? (reader: %s)",
                                     census.face_lines, faces_read,
                                     Echo(absl::StripAsciiWhitespace(reader.Warning()), 200)));
  }
  TriangleMesh mesh;
  mesh.name = std::string(name);
  const size_t nv = attrib.vertices.size() / 3;
  mesh.positions.resize(nv);
  for (size_t i = 0; i < nv; ++i) {
    mesh.positions[i] = {attrib.vertices[3 * i], attrib.vertices[3 * i + 1],
                         attrib.vertices[3 * i + 2]};
  }
  // OBJ normals belong to face corners; they are vertex normals only when
  // every corner of a vertex names the same one.
  std::vector<int> normal_of(nv, -1);
  bool vertex_normals = !attrib.normals.empty();
  std::vector<uint32_t> corners;
  uint64_t ordinal = 0;  // the face's place in the file, as the census counts
  auto next_long = census.long_faces.begin();
  for (const tinyobj::shape_t& shape : reader.GetShapes()) {
    const std::vector<tinyobj::index_t>& indices = shape.mesh.indices;
    size_t offset = 0;
    for (const unsigned int kept : shape.mesh.num_face_vertices) {
      // The reader's count is the true one modulo 256.
      uint64_t count = kept;
      size_t line_number = 0;
      if (next_long != census.long_faces.end() && next_long->ordinal == ordinal) {
        count = next_long->corners;
        line_number = next_long->line_number;
        ++next_long;
      }
      ++ordinal;
      if (count % 256 != kept || count > indices.size() - offset) {
        return Malformed(
            name,
            absl::StrFormat("face %d%s: the OBJ reader's corner count (%d, of %d corners "
                            "left in its group) does not match the file's (%d); refusing "
                            "rather than reading misaligned corners",
                            ordinal, line_number ? absl::StrFormat(" (line %d)", line_number) : "",
                            kept, indices.size() - offset, count));
      }
      corners.clear();
      for (size_t c = 0; c < count; ++c) {
        const tinyobj::index_t& index = indices[offset + c];
        if (index.vertex_index < 0 || static_cast<size_t>(index.vertex_index) >= nv) {
          return Malformed(name, absl::StrFormat("a face uses vertex %d but the file has %d "
                                                 "vertices (a truncated file?)",
                                                 index.vertex_index + 1, nv));
        }
        corners.push_back(static_cast<uint32_t>(index.vertex_index));
        if (vertex_normals) {
          int& n = normal_of[index.vertex_index];
          if (index.normal_index < 0 ||
              static_cast<size_t>(index.normal_index) * 3 + 2 >= attrib.normals.size() ||
              (n >= 0 && n != index.normal_index)) {
            vertex_normals = false;
          } else {
            n = index.normal_index;
          }
        }
      }
      offset += count;
      AddPolygon(corners, &mesh);
    }
    if (offset != indices.size()) {
      return Malformed(name, absl::StrFormat("the OBJ reader kept %d face corners in the group "
                                             "ending with face %d but its faces count %d; "
                                             "refusing rather than reading misaligned corners",
                                             indices.size(), ordinal, offset));
    }
  }
  if (vertex_normals) {
    mesh.normals.resize(nv);
    for (size_t i = 0; i < nv; ++i) {
      if (normal_of[i] < 0) continue;  // unused vertex: any unit vector
      const size_t n = static_cast<size_t>(normal_of[i]) * 3;
      mesh.normals[i] = {attrib.normals[n], attrib.normals[n + 1], attrib.normals[n + 2]};
    }
    for (Vec3& n : mesh.normals) {
      if (n == Vec3{}) n = {0, 0, 1};
    }
  }
  return mesh;
}

// ---------------------------------------------------------------- PLY

// Reads the current value of a scalar property as a double. The property's
// type is resolved once per element (Resolve), not once per value.
using ScalarGetter = double (*)(const CgalPlyNumber*);

template <typename T>
double GetScalar(const CgalPlyNumber* p) {
  return static_cast<double>(
      static_cast<const CGAL::IO::internal::PLY_read_typed_number<T>*>(p)->buffer());
}

template <typename T>
bool Is(const CgalPlyNumber* p) {
  return dynamic_cast<const CGAL::IO::internal::PLY_read_typed_number<T>*>(p) != nullptr;
}

// The getter for a scalar property of any numeric PLY type; nullptr for lists.
ScalarGetter Resolve(const CgalPlyNumber* p) {
  if (Is<double>(p)) return &GetScalar<double>;
  if (Is<float>(p)) return &GetScalar<float>;
  if (Is<int32_t>(p)) return &GetScalar<int32_t>;
  if (Is<uint32_t>(p)) return &GetScalar<uint32_t>;
  if (Is<int16_t>(p)) return &GetScalar<int16_t>;
  if (Is<uint16_t>(p)) return &GetScalar<uint16_t>;
  if (Is<int8_t>(p)) return &GetScalar<int8_t>;
  if (Is<uint8_t>(p)) return &GetScalar<uint8_t>;
  return nullptr;
}

// A face's corner list of any integer type, copied into `out`; false when the
// property is not an integer list.
bool ListValue(const CgalPlyNumber* p, std::vector<int64_t>* out) {
  using CGAL::IO::internal::PLY_read_typed_list;
  out->clear();
  auto copy = [out](const auto& buffer) {
    out->assign(buffer.begin(), buffer.end());
    return true;
  };
  if (auto* q = dynamic_cast<const PLY_read_typed_list<int32_t>*>(p)) return copy(q->buffer());
  if (auto* q = dynamic_cast<const PLY_read_typed_list<uint32_t>*>(p)) return copy(q->buffer());
  if (auto* q = dynamic_cast<const PLY_read_typed_list<int16_t>*>(p)) return copy(q->buffer());
  if (auto* q = dynamic_cast<const PLY_read_typed_list<uint16_t>*>(p)) return copy(q->buffer());
  if (auto* q = dynamic_cast<const PLY_read_typed_list<int8_t>*>(p)) return copy(q->buffer());
  if (auto* q = dynamic_cast<const PLY_read_typed_list<uint8_t>*>(p)) return copy(q->buffer());
  return false;
}

// CGAL's list reader resizes to the stored count before reading it: a 32-bit
// count in a broken file would allocate gigabytes. Only 8- and 16-bit counts
// (what writers use: "property list uchar int vertex_indices") are read.
bool HasNarrowListCount(const CgalPlyNumber* p) {
  using CGAL::IO::internal::PLY_read_typed_list_with_typed_size;
  auto narrow = [p](auto index_tag) {
    using Index = decltype(index_tag);
    return dynamic_cast<const PLY_read_typed_list_with_typed_size<uint8_t, Index>*>(p) ||
           dynamic_cast<const PLY_read_typed_list_with_typed_size<int8_t, Index>*>(p) ||
           dynamic_cast<const PLY_read_typed_list_with_typed_size<uint16_t, Index>*>(p) ||
           dynamic_cast<const PLY_read_typed_list_with_typed_size<int16_t, Index>*>(p);
  };
  return narrow(int32_t{}) || narrow(uint32_t{}) || narrow(int16_t{}) || narrow(uint16_t{}) ||
         narrow(int8_t{}) || narrow(uint8_t{}) || narrow(float{}) || narrow(double{});
}

// CGAL's header parser appends a "property" line to the last element
// without checking that there is one: a property before any element writes
// through a null pointer (found by fuzz/ply_fuzzer). The header is checked
// here first: it ends with end_header, and every property follows an element.
absl::Status CheckPlyHeader(absl::string_view bytes, absl::string_view name) {
  constexpr size_t kMaxHeader = size_t{1} << 20;
  bool element = false;
  size_t line_number = 0, start = 0;
  // Lines and keywords as CGAL reads them: std::getline, then >> keyword.
  while (start < bytes.size() && start < kMaxHeader) {
    size_t end = bytes.find('\n', start);
    if (end == absl::string_view::npos) end = bytes.size();
    const absl::string_view line = bytes.substr(start, end - start);
    start = end + 1;
    ++line_number;
    std::vector<absl::string_view> tokens =
        absl::StrSplit(line, absl::ByAnyChar(" \t\r\v\f"), absl::SkipEmpty());
    // CGAL takes line 1 as the signature and line 2 as the format line,
    // whatever they hold; keywords count from line 3.
    if (tokens.empty() || line_number <= 2) continue;
    if (tokens[0] == "end_header") return absl::OkStatus();
    if (tokens[0] == "element") element = true;
    if (tokens[0] == "property" && !element) {
      return Malformed(name, absl::StrFormat("header line %d: a property before any element "
                                             "('%s'); properties follow their 'element' line",
                                             line_number, Echo(line)));
    }
  }
  return Malformed(name, "the PLY header has no 'end_header' line in its first 1 MiB");
}

// The format line (line 2, as CGAL reads it) says ascii.
bool IsAsciiPly(absl::string_view bytes) {
  std::vector<absl::string_view> lines = absl::StrSplit(bytes, absl::MaxSplits('\n', 2));
  if (lines.size() < 2) return false;
  std::vector<absl::string_view> tokens =
      absl::StrSplit(lines[1], absl::ByAnyChar(" \t\r\v\f"), absl::SkipEmpty());
  return tokens.size() >= 2 && tokens[1] == "ascii";
}

// ASCII PLY integers that do not fit their declared type: CGAL reads an
// 8-bit value as a short and casts it (a uchar list count of 259 becomes 3,
// a uchar 300 becomes 44), and an unsigned one takes "-1" as its largest
// value. So the tokens an integer property is about to read are checked
// first, and the stream put back where it was.
struct IntRange {
  int64_t lo = 0, hi = 0;
  const char* type = "";
};
template <typename T>
std::optional<IntRange> RangeOf() {
  if constexpr (std::is_integral_v<T>) {
    return IntRange{std::numeric_limits<T>::min(), std::numeric_limits<T>::max(),
                    sizeof(T) == 1 ? (std::is_signed_v<T> ? "char" : "uchar")
                    : sizeof(T) == 2 ? (std::is_signed_v<T> ? "short" : "ushort")
                                     : (std::is_signed_v<T> ? "int" : "uint")};
  }
  return std::nullopt;
}

// The ranges a property reads: a scalar's; a list's count and items.
struct PropertyRanges {
  std::optional<IntRange> scalar, count, item;
  bool list = false;
};

template <typename Count, typename... Items>
void ListRanges(const CgalPlyNumber* p, PropertyRanges* out) {
  using CGAL::IO::internal::PLY_read_typed_list_with_typed_size;
  (void)((dynamic_cast<const PLY_read_typed_list_with_typed_size<Count, Items>*>(p) &&
          (*out = PropertyRanges{std::nullopt, RangeOf<Count>(), RangeOf<Items>(), true}, true)) ||
         ...);
}

PropertyRanges RangesOf(const CgalPlyNumber* p) {
  PropertyRanges r;
  auto scalar = [&](auto type) {
    using T = decltype(type);
    if (!r.scalar && Is<T>(p)) r.scalar = RangeOf<T>();
  };
  scalar(int8_t{}), scalar(uint8_t{}), scalar(int16_t{}), scalar(uint16_t{}), scalar(int32_t{}),
      scalar(uint32_t{});
  if (r.scalar) return r;
  auto list = [&](auto count) {
    if (!r.list) {
      ListRanges<decltype(count), int8_t, uint8_t, int16_t, uint16_t, int32_t, uint32_t, float,
                 double>(p, &r);
    }
  };
  list(uint8_t{}), list(int8_t{}), list(uint16_t{}), list(int16_t{});
  return r;
}

// OK when the next tokens of `in` fit `ranges` (tokens that are no integer
// at all are CGAL's to refuse); `in` is left where it was.
absl::Status CheckAsciiIntegers(std::istream& in, const PropertyRanges& ranges,
                                absl::string_view what, absl::string_view name) {
  if (!ranges.scalar && !ranges.count) return absl::OkStatus();
  const std::streampos start = in.tellg();
  absl::Status status;
  auto next = [&](const std::optional<IntRange>& range, int64_t* value) {
    std::string token;
    if (!(in >> token) || !absl::SimpleAtoi(token, value)) return false;
    if (range && (*value < range->lo || *value > range->hi)) {
      status = Malformed(name, absl::StrFormat("%s: %s does not fit its type %s (%d..%d)", what,
                                               Echo(token), range->type, range->lo, range->hi));
      return false;
    }
    return true;
  };
  int64_t count = 0, item = 0;
  if (ranges.scalar) {
    next(ranges.scalar, &item);
  } else if (next(ranges.count, &count) && ranges.item) {
    for (int64_t i = 0; i < count && next(ranges.item, &item); ++i) {
    }
  }
  in.clear();
  in.seekg(start);
  return status;
}

absl::StatusOr<TriangleMesh> LoadPly(absl::string_view bytes, absl::string_view name,
                                     const MeshLoadOptions& options) {
  // The plainest binary files (what the Python package writes for arrays)
  // without the istream (mesh/plain_ply.h); the same mesh.
  if (std::optional<TriangleMesh> plain =
          ReadPlainBinaryPly(bytes, name, options.weight_property)) {
    return *std::move(plain);
  }
  RETURN_IF_ERROR(CheckPlyHeader(bytes, name));
  std::istringstream in(std::string(bytes), std::ios::in | std::ios::binary);
  CgalPlyReader reader(/*verbose=*/false);
  if (!reader.init(in)) {
    return Malformed(name, "not a valid PLY header (it must start with 'ply', give a 'format' "
                           "line and end with 'end_header')");
  }
  TriangleMesh mesh;
  mesh.name = std::string(name);
  bool have_vertices = false;
  const bool ascii = IsAsciiPly(bytes);
  for (size_t e = 0; e < reader.number_of_elements(); ++e) {
    CgalPlyElement& element = reader.element(e);
    const size_t items = element.number_of_items();
    const size_t props = element.number_of_properties();
    if (props == 0 || items == 0) continue;
    // Every item of an element with properties takes at least one byte.
    if (items > bytes.size()) {
      return Malformed(name, absl::StrFormat("element '%s' declares %d items, more than the %d "
                                             "bytes of the file can hold (a truncated file?)",
                                             Echo(element.name()), items, bytes.size()));
    }
    for (size_t k = 0; k < props; ++k) {
      CgalPlyNumber* p = element.property(k);
      if (Resolve(p) == nullptr && !HasNarrowListCount(p)) {
        return Malformed(name, absl::StrFormat("property '%s' of element '%s' is a list with a "
                                               "32-bit count; write 'property list uchar int %s'",
                                               Echo(p->name()), Echo(element.name()),
                                               Echo(p->name())));
      }
    }
    const bool is_vertex = element.name() == "vertex";
    const bool is_face = element.name() == "face";
    int ix = -1, iy = -1, iz = -1, inx = -1, iny = -1, inz = -1, iw = -1, ifaces = -1;
    for (size_t k = 0; k < props; ++k) {
      const std::string& pn = element.property(k)->name();
      const bool scalar = Resolve(element.property(k)) != nullptr;
      if (is_vertex && scalar) {
        if (pn == "x") ix = k;
        if (pn == "y") iy = k;
        if (pn == "z") iz = k;
        if (pn == "nx") inx = k;
        if (pn == "ny") iny = k;
        if (pn == "nz") inz = k;
        if (!options.weight_property.empty() && pn == options.weight_property) iw = k;
      }
      if (is_face && !scalar && (pn == "vertex_indices" || pn == "vertex_index")) ifaces = k;
    }
    if (is_vertex) {
      if (ix < 0 || iy < 0 || iz < 0) {
        return Malformed(name, "the vertex element needs scalar properties x, y and z");
      }
      if (!options.weight_property.empty() && iw < 0) {
        return Malformed(name, absl::StrFormat("the vertex element has no scalar property '%s' "
                                               "to read weights from",
                                               Echo(options.weight_property)));
      }
      have_vertices = true;
      mesh.positions.reserve(items);
      const bool normals = inx >= 0 && iny >= 0 && inz >= 0;
      if (normals) mesh.normals.reserve(items);
      if (iw >= 0) mesh.weights.reserve(items);
    } else if (is_face && ifaces < 0) {
      return Malformed(name, "the face element needs a list property 'vertex_indices'");
    }
    std::vector<int64_t> list;
    std::vector<uint32_t> corners;
    auto getter = [&element](int k) {
      return k < 0 ? ScalarGetter{nullptr} : Resolve(element.property(k));
    };
    const ScalarGetter gx = getter(ix), gy = getter(iy), gz = getter(iz), gnx = getter(inx),
                       gny = getter(iny), gnz = getter(inz), gw = getter(iw);
    std::vector<PropertyRanges> ranges;
    if (ascii) {
      for (size_t k = 0; k < props; ++k) ranges.push_back(RangesOf(element.property(k)));
    }
    for (size_t j = 0; j < items; ++j) {
      if (options.check && (j & 0xffff) == 0) RETURN_IF_ERROR(options.check());
      for (size_t k = 0; k < props; ++k) {
        if (ascii) {
          RETURN_IF_ERROR(CheckAsciiIntegers(
              in, ranges[k],
              absl::StrFormat("property '%s' of %s %d", Echo(element.property(k)->name()),
                              Echo(element.name()), j),
              name));
        }
        element.property(k)->get(in);
      }
      if (!in) {
        return Malformed(name, absl::StrFormat("the file ends or breaks inside %s %d of %d (a "
                                               "truncated or malformed file?)",
                                               Echo(element.name()), j, items));
      }
      if (is_vertex) {
        mesh.positions.push_back({gx(element.property(ix)), gy(element.property(iy)),
                                  gz(element.property(iz))});
        if (gnx && gny && gnz) {
          mesh.normals.push_back({gnx(element.property(inx)), gny(element.property(iny)),
                                  gnz(element.property(inz))});
        }
        if (gw) mesh.weights.push_back(gw(element.property(iw)));
      } else if (is_face) {
        ListValue(element.property(ifaces), &list);
        if (list.size() < 3) {
          return Malformed(name, absl::StrFormat("face %d has %d corners; a face needs at least "
                                                 "three",
                                                 j, list.size()));
        }
        corners.clear();
        for (int64_t c : list) {
          // Vertices come before faces in every writer's files; a face that
          // names a vertex past them is refused here, with the index.
          if (c < 0 || static_cast<uint64_t>(c) >= mesh.positions.size()) {
            return Malformed(name,
                             absl::StrFormat("face %d uses vertex index %d, but the file "
                                             "has %d vertices before its faces (indices "
                                             "0..%d)",
                                             j, c, mesh.positions.size(),
                                             static_cast<int64_t>(mesh.positions.size()) - 1));
          }
          corners.push_back(static_cast<uint32_t>(c));
        }
        AddPolygon(corners, &mesh);
      }
    }
  }
  if (!have_vertices) return Malformed(name, "the file has no vertex element");
  return mesh;
}

}  // namespace

absl::StatusOr<TriangleMesh> LoadMesh(absl::string_view bytes, absl::string_view untrusted_name,
                                      const MeshLoadOptions& options) {
  const std::string name = Echo(untrusted_name, kMaxNameEcho);
  if (bytes.size() > options.max_bytes) {
    return absl::ResourceExhaustedError(absl::StrFormat(
        "mesh '%s' is %d bytes, past the limit of %d bytes", name, bytes.size(),
        options.max_bytes));
  }
  if (bytes.empty()) {
    return absl::InvalidArgumentError(absl::StrFormat("mesh '%s' is empty (0 bytes)", name));
  }
  const ModelFormat format = options.format.value_or(
      absl::StartsWith(bytes, "ply") ? ModelFormat::kPly : ModelFormat::kObj);
  if (format != ModelFormat::kObj && format != ModelFormat::kPly) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "mesh '%s': %s is not a mesh format (obj or ply)", name, ModelFormatName(format)));
  }
  absl::StatusOr<TriangleMesh> mesh;
  try {
    mesh =
        format == ModelFormat::kPly ? LoadPly(bytes, name, options) : LoadObj(bytes, name, options);
  } catch (const std::bad_alloc&) {
    return absl::ResourceExhaustedError(
        absl::StrFormat("mesh '%s' needs more memory than is available", name));
  } catch (const std::exception& e) {
    return Malformed(name, absl::StrFormat("the reader failed: %s", Echo(e.what())));
  }
  if (!mesh.ok()) return mesh.status();
  RETURN_IF_ERROR(FinalizeMesh(&*mesh));
  return mesh;
}

absl::StatusOr<TriangleMesh> LoadMeshFile(const std::string& path, const MeshLoadOptions& options) {
  std::ifstream file(path, std::ios::binary | std::ios::ate);
  if (!file) return absl::NotFoundError(absl::StrFormat("cannot open mesh file '%s'", path));
  const std::streamoff size = file.tellg();
  if (size < 0) return absl::NotFoundError(absl::StrFormat("cannot read mesh file '%s'", path));
  if (static_cast<uint64_t>(size) > options.max_bytes) {
    return absl::ResourceExhaustedError(absl::StrFormat(
        "mesh '%s' is %d bytes, past the limit of %d bytes", path, size, options.max_bytes));
  }
  std::string bytes(static_cast<size_t>(size), '\0');
  file.seekg(0);
  if (!file.read(bytes.data(), size)) {
    return absl::NotFoundError(absl::StrFormat("cannot read mesh file '%s'", path));
  }
  MeshLoadOptions resolved = options;
  if (!resolved.format && !absl::StartsWith(bytes, "ply")) {
    // The file name's mesh format (request/model_files.h), if it names one.
    const std::optional<ModelFormat> named = ModelFormatOfPath(path);
    if (named == ModelFormat::kObj || named == ModelFormat::kPly) resolved.format = named;
  }
  return LoadMesh(bytes, path, resolved);
}

uint64_t MeshParseMemoryBytes(ModelFormat format, absl::string_view bytes) {
  const uint64_t per_byte = format != ModelFormat::kPly || IsAsciiPly(bytes) ? 32 : 64;
  return (uint64_t{1} << 20) + per_byte * bytes.size();
}

}  // namespace sfc
