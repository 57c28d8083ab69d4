#include "client/sample_writer.h"

#include <algorithm>
#include <charconv>
#include <cstring>
#include <vector>

#include "absl/strings/str_format.h"
#include "base/status_macros.h"

namespace sfc {
namespace {

template <typename T>
void AppendShortest(std::string* out, T value) {
  char buf[32];
  const auto result = std::to_chars(buf, buf + sizeof(buf), value);
  out->append(buf, result.ptr);
}

void AppendUint(std::string* out, uint64_t value) {
  char buf[24];
  const auto result = std::to_chars(buf, buf + sizeof(buf), value);
  out->append(buf, result.ptr);
}

template <typename T>
void AppendBinary(std::string* out, T value) {
  // x86-64 and aarch64 are little-endian, as binary_little_endian requires.
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  out->append(bytes, sizeof(T));
}

// The columns a file can hold, in the order of CSV and NPY.
enum class Col { kIndex, kU, kV, kX, kY, kZ, kNx, kNy, kNz, kDensity, kCurvePosition, kFace,
                 kTriangle };
constexpr const char* kColumnNames[] = {"index", "u",  "v",  "x",       "y",
                                        "z",     "nx", "ny", "nz",      "density",
                                        "curve_position", "face", "triangle"};
const char* Name(Col c) { return kColumnNames[static_cast<int>(c)]; }
bool IsReal(Col c) { return c != Col::kIndex && c != Col::kFace && c != Col::kTriangle; }

// Whether the request's fields make column c.
bool Made(Col c, const SampleFields& f) {
  switch (c) {
    case Col::kNx: case Col::kNy: case Col::kNz: return f.normal;
    case Col::kDensity: return f.density;
    case Col::kCurvePosition: return f.curve_position;
    case Col::kFace: return f.face;
    case Col::kTriangle: return f.triangle;
    default: return true;
  }
}

// The request flag that makes an optional column.
const char* FlagOf(Col c) {
  switch (c) {
    case Col::kNx: case Col::kNy: case Col::kNz: return "--normals";
    case Col::kDensity: return "--density-column";
    case Col::kCurvePosition: return "--curve-position";
    case Col::kFace: return "--face";
    default: return "--triangle";
  }
}

const std::vector<double>& Real(const SampleBatch& b, Col c) {
  switch (c) {
    case Col::kU: return b.u;
    case Col::kV: return b.v;
    case Col::kX: return b.x;
    case Col::kY: return b.y;
    case Col::kZ: return b.z;
    case Col::kNx: return b.nx;
    case Col::kNy: return b.ny;
    case Col::kNz: return b.nz;
    case Col::kDensity: return b.density;
    default: return b.curve_position;
  }
}

absl::Status WriteAll(std::FILE* f, const std::string& data) {
  if (std::fwrite(data.data(), 1, data.size(), f) != data.size()) {
    return absl::UnavailableError(
        absl::StrFormat("writing the output failed: %s", std::strerror(errno)));
  }
  return absl::OkStatus();
}

// The file's columns in its order (CSV and NPY: kColumnNames' order; PLY:
// x y z, normals, u v index, then the rest), the request's fields filtered by
// `columns` (empty: all).
absl::StatusOr<std::vector<Col>> Layout(OutputFormat format, const SampleFields& fields,
                                        const std::vector<std::string>& columns) {
  std::vector<Col> order;
  if (format == OutputFormat::kPlyBinary || format == OutputFormat::kPlyAscii) {
    order = {Col::kX, Col::kY, Col::kZ, Col::kNx, Col::kNy, Col::kNz, Col::kU,
             Col::kV, Col::kIndex, Col::kDensity, Col::kCurvePosition, Col::kFace,
             Col::kTriangle};
  } else {
    for (int c = 0; c <= static_cast<int>(Col::kTriangle); ++c)
      order.push_back(static_cast<Col>(c));
  }
  std::vector<bool> wanted(order.size(), columns.empty());
  for (const std::string& name : columns) {
    int found = -1;
    for (int c = 0; c <= static_cast<int>(Col::kTriangle); ++c) {
      if (name == kColumnNames[c]) found = c;
    }
    if (found < 0) {
      std::string all;
      for (const char* n : kColumnNames) all += (all.empty() ? "" : ",") + std::string(n);
      return absl::InvalidArgumentError(absl::StrFormat(
          "--columns: unknown column \"%s\"; the columns are %s", name.substr(0, 40), all));
    }
    const Col c = static_cast<Col>(found);
    if (!Made(c, fields)) {
      return absl::InvalidArgumentError(
          absl::StrFormat("--columns: \"%s\" needs %s", name, FlagOf(c)));
    }
    wanted[found] = true;
  }
  std::vector<Col> layout;
  for (Col c : order) {
    if (Made(c, fields) && wanted[static_cast<int>(c)]) layout.push_back(c);
  }
  const bool ply = format == OutputFormat::kPlyBinary || format == OutputFormat::kPlyAscii;
  if (ply && (layout.size() < 3 || layout[0] != Col::kX || layout[1] != Col::kY ||
              layout[2] != Col::kZ)) {
    return absl::InvalidArgumentError(
        "--columns: PLY output needs the x, y and z columns (use CSV or NPY for others)");
  }
  return layout;
}

}  // namespace

SampleWriter::SampleWriter(std::FILE* out, bool owns, OutputFormat format,
                           const SampleFields& fields, OutputPrecision precision)
    : out_(out), owns_(owns), format_(format), fields_(fields), precision_(precision) {}

absl::Status SampleWriter::CheckColumns(OutputFormat format, const SampleFields& fields,
                                        const std::vector<std::string>& columns) {
  return Layout(format, fields, columns).status();
}

SampleFields SampleWriter::SourceFields(SampleFields fields,
                                        const std::vector<std::string>& columns) {
  if (columns.empty()) return fields;
  auto named = [&](std::initializer_list<const char*> names) {
    for (const char* name : names) {
      if (std::find(columns.begin(), columns.end(), name) != columns.end()) return true;
    }
    return false;
  };
  fields.uv = named({"u", "v"});
  fields.xyz = named({"x", "y", "z"});
  fields.normal = fields.normal && named({"nx", "ny", "nz"});
  fields.density = fields.density && named({"density"});
  fields.curve_position = fields.curve_position && named({"curve_position"});
  // face and triangle stay as asked: the engine refuses them on a surface
  // without faces or triangles, whatever the file keeps.
  if (!fields.uv && !fields.xyz && !fields.normal && !fields.density && !fields.curve_position) {
    fields.uv = true;
  }
  return fields;
}

void SampleWriter::AppendNumber(std::string* out, double value) const {
  if (precision_ == OutputPrecision::kFloat32) {
    AppendShortest(out, static_cast<float>(value));
  } else {
    AppendShortest(out, value);
  }
}

// NPY format 1.0: magic, version, a little-endian uint16 header length, and a
// Python dict literal padded with spaces and a newline so the data starts at
// a multiple of 64 bytes (numpy/lib/format.py).
std::string SampleWriter::NpyHeader(uint64_t count) const {
  const char* real = precision_ == OutputPrecision::kFloat32 ? "'<f4'" : "'<f8'";
  std::string descr;
  for (int id : layout_) {
    const Col c = static_cast<Col>(id);
    descr += absl::StrFormat("%s('%s', %s)", descr.empty() ? "[" : ", ", Name(c),
                             c == Col::kIndex ? "'<u8'" : IsReal(c) ? real : "'<u4'");
  }
  descr += "]";
  std::string dict =
      absl::StrFormat("{'descr': %s, 'fortran_order': False, 'shape': (%d,), }", descr, count);
  const size_t unpadded = 10 + dict.size() + 1;
  dict.append((64 - unpadded % 64) % 64, ' ');
  dict += '\n';
  std::string h = "\x93NUMPY";
  h += '\x01';
  h += '\x00';
  AppendBinary(&h, static_cast<uint16_t>(dict.size()));
  return h + dict;
}

SampleWriter::~SampleWriter() {
  if (staging_) std::fclose(staging_);
  if (owns_ && out_) std::fclose(out_);
}

absl::StatusOr<std::unique_ptr<SampleWriter>> SampleWriter::Open(
    const std::string& path, OutputFormat format, const SampleFields& fields,
    std::optional<uint64_t> expected_count, OutputPrecision precision,
    const std::vector<std::string>& columns) {
  ASSIGN_OR_RETURN(const std::vector<Col> layout, Layout(format, fields, columns));
  std::FILE* f = path == "-" ? stdout : std::fopen(path.c_str(), "wb");
  if (!f) {
    return absl::InvalidArgumentError(
        absl::StrFormat("cannot open \"%s\" for writing: %s", path, std::strerror(errno)));
  }
  auto writer =
      std::unique_ptr<SampleWriter>(new SampleWriter(f, path != "-", format, fields, precision));
  for (Col c : layout) writer->layout_.push_back(static_cast<int>(c));
  writer->expected_ = expected_count;
  if (format == OutputFormat::kCsv) {
    RETURN_IF_ERROR(writer->WriteHeader(0));
  } else if (expected_count) {
    RETURN_IF_ERROR(writer->WriteHeader(*expected_count));
  } else {
    writer->staging_ = std::tmpfile();
    if (!writer->staging_) {
      return absl::InternalError("cannot create a temporary file for PLY or NPY output");
    }
  }
  return writer;
}

absl::Status SampleWriter::WriteHeader(uint64_t count) {
  std::string h;
  if (format_ == OutputFormat::kCsv) {
    for (int id : layout_) h += (h.empty() ? "" : ",") + std::string(Name(static_cast<Col>(id)));
    h += "\n";
    return WriteAll(out_, h);
  }
  if (format_ == OutputFormat::kNpy) {
    if (NpyHeader(count).size() > 65535 + 10) return absl::InternalError("NPY header too long");
    return WriteAll(out_, NpyHeader(count));
  }
  h = "ply\n";
  h += format_ == OutputFormat::kPlyAscii ? "format ascii 1.0\n"
                                          : "format binary_little_endian 1.0\n";
  h += "comment sfcsampler samples in curve order\n";
  h += absl::StrFormat("element vertex %d\n", count);
  const char* type = precision_ == OutputPrecision::kFloat32 ? "float" : "double";
  for (int id : layout_) {
    const Col c = static_cast<Col>(id);
    h += absl::StrFormat("property %s %s\n", IsReal(c) ? type : "uint", Name(c));
  }
  h += "end_header\n";
  return WriteAll(out_, h);
}

absl::Status SampleWriter::WriteRows(std::FILE* to, const SampleBatch& b) {
  buffer_.clear();
  if (format_ == OutputFormat::kNpy || format_ == OutputFormat::kPlyBinary) {
    PackBinary(b);
    return WriteAll(to, buffer_);
  }
  const char separator = format_ == OutputFormat::kCsv ? ',' : ' ';
  for (size_t i = 0; i < b.size(); ++i) {
    bool first = true;
    for (int id : layout_) {
      const Col c = static_cast<Col>(id);
      if (!first) buffer_ += separator;
      first = false;
      if (c == Col::kIndex) {
        AppendUint(&buffer_, b.index[i]);
      } else if (c == Col::kFace) {
        AppendUint(&buffer_, b.face[i]);
      } else if (c == Col::kTriangle) {
        AppendUint(&buffer_, b.triangle[i]);
      } else {
        AppendNumber(&buffer_, Real(b, c)[i]);
      }
    }
    buffer_ += '\n';
  }
  return WriteAll(to, buffer_);
}

void SampleWriter::PackBinary(const SampleBatch& b) {
  // Fixed-size little-endian records (x86-64 and aarch64 are little-endian,
  // as both formats require), filled a column at a time: each column is
  // copied into its place in every record of the buffer.
  const size_t n = b.size();
  const size_t real = precision_ == OutputPrecision::kFloat32 ? sizeof(float) : sizeof(double);
  struct Column {
    const double* real = nullptr;     // a float column, written in the precision
    const uint64_t* index = nullptr;  // the index: uint64 in NPY, uint32 in PLY
    const uint32_t* uint = nullptr;   // face or triangle
  };
  std::vector<Column> columns;
  for (int id : layout_) {
    const Col c = static_cast<Col>(id);
    if (c == Col::kIndex) {
      columns.push_back({nullptr, b.index.data(), nullptr});
    } else if (c == Col::kFace) {
      columns.push_back({nullptr, nullptr, b.face.data()});
    } else if (c == Col::kTriangle) {
      columns.push_back({nullptr, nullptr, b.triangle.data()});
    } else {
      columns.push_back({Real(b, c).data(), nullptr, nullptr});
    }
  }
  const bool npy = format_ == OutputFormat::kNpy;
  const size_t index_width = npy ? sizeof(uint64_t) : sizeof(uint32_t);
  size_t record = 0;
  for (const Column& c : columns)
    record += c.real ? real : c.index ? index_width : sizeof(uint32_t);
  buffer_.resize(n * record);
  char* out = buffer_.data();
  size_t offset = 0;
  for (const Column& c : columns) {
    char* at = out + offset;
    if (c.real && real == sizeof(float)) {
      for (size_t i = 0; i < n; ++i, at += record) {
        const float f = static_cast<float>(c.real[i]);
        std::memcpy(at, &f, sizeof f);
      }
      offset += sizeof(float);
    } else if (c.real) {
      for (size_t i = 0; i < n; ++i, at += record) std::memcpy(at, &c.real[i], sizeof(double));
      offset += sizeof(double);
    } else if (c.index && npy) {
      for (size_t i = 0; i < n; ++i, at += record) std::memcpy(at, &c.index[i], sizeof(uint64_t));
      offset += sizeof(uint64_t);
    } else if (c.index) {
      for (size_t i = 0; i < n; ++i, at += record) {
        const uint32_t k = static_cast<uint32_t>(c.index[i]);
        std::memcpy(at, &k, sizeof k);
      }
      offset += sizeof(uint32_t);
    } else {
      for (size_t i = 0; i < n; ++i, at += record) std::memcpy(at, &c.uint[i], sizeof(uint32_t));
      offset += sizeof(uint32_t);
    }
  }
}

absl::Status SampleWriter::Write(const SampleBatch& batch) {
  const bool ply = format_ == OutputFormat::kPlyBinary || format_ == OutputFormat::kPlyAscii;
  const bool index = std::find(layout_.begin(), layout_.end(), static_cast<int>(Col::kIndex)) !=
                     layout_.end();
  if (ply && index && !batch.index.empty() && batch.index.back() > UINT32_MAX) {
    return absl::InvalidArgumentError(
        "PLY stores the sample index as uint32; use CSV for indices >= 2^32");
  }
  RETURN_IF_ERROR(WriteRows(staging_ ? staging_ : out_, batch));
  written_ += batch.size();
  return absl::OkStatus();
}

absl::Status SampleWriter::Finish() {
  if (expected_ && *expected_ != written_) {
    return absl::DataLossError(absl::StrFormat(
        "expected %d samples but received %d; the output is incomplete", *expected_, written_));
  }
  if (staging_) {
    RETURN_IF_ERROR(WriteHeader(written_));
    std::rewind(staging_);
    char buf[1 << 16];
    size_t n;
    while ((n = std::fread(buf, 1, sizeof(buf), staging_)) > 0) {
      if (std::fwrite(buf, 1, n, out_) != n)
        return absl::UnavailableError("writing the output failed");
    }
  }
  if (std::fflush(out_) != 0) return absl::UnavailableError("flushing the output failed");
  return absl::OkStatus();
}

}  // namespace sfc
