#include "client/sample_writer.h"

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

absl::Status WriteAll(std::FILE* f, const std::string& data) {
  if (std::fwrite(data.data(), 1, data.size(), f) != data.size()) {
    return absl::UnavailableError(absl::StrFormat("writing the output failed: %s", std::strerror(errno)));
  }
  return absl::OkStatus();
}

}  // namespace

SampleWriter::SampleWriter(std::FILE* out, bool owns, OutputFormat format, const SampleFields& fields,
                           OutputPrecision precision)
    : out_(out), owns_(owns), format_(format), fields_(fields), precision_(precision) {}

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
  const char* f = precision_ == OutputPrecision::kFloat32 ? "'<f4'" : "'<f8'";
  std::string descr = "[('index', '<u8')";
  std::vector<const char*> names = {"u", "v", "x", "y", "z"};
  if (fields_.normal) names.insert(names.end(), {"nx", "ny", "nz"});
  if (fields_.density) names.push_back("density");
  if (fields_.curve_position) names.push_back("curve_position");
  for (const char* name : names) descr += absl::StrFormat(", ('%s', %s)", name, f);
  if (fields_.face) descr += ", ('face', '<u4')";
  if (fields_.triangle) descr += ", ('triangle', '<u4')";
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
    std::optional<uint64_t> expected_count, OutputPrecision precision) {
  std::FILE* f = path == "-" ? stdout : std::fopen(path.c_str(), "wb");
  if (!f) {
    return absl::InvalidArgumentError(
        absl::StrFormat("cannot open \"%s\" for writing: %s", path, std::strerror(errno)));
  }
  auto writer = std::unique_ptr<SampleWriter>(new SampleWriter(f, path != "-", format, fields, precision));
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
    h = "index,u,v,x,y,z";
    if (fields_.normal) h += ",nx,ny,nz";
    if (fields_.density) h += ",density";
    if (fields_.curve_position) h += ",curve_position";
    if (fields_.face) h += ",face";
    if (fields_.triangle) h += ",triangle";
    h += "\n";
    return WriteAll(out_, h);
  }
  if (format_ == OutputFormat::kNpy) {
    if (NpyHeader(count).size() > 65535 + 10) return absl::InternalError("NPY header too long");
    return WriteAll(out_, NpyHeader(count));
  }
  h = "ply\n";
  h += format_ == OutputFormat::kPlyAscii ? "format ascii 1.0\n" : "format binary_little_endian 1.0\n";
  h += "comment sfcsampler samples in curve order\n";
  h += absl::StrFormat("element vertex %d\n", count);
  const char* type = precision_ == OutputPrecision::kFloat32 ? "float" : "double";
  auto property = [&](const char* name) { h += absl::StrFormat("property %s %s\n", type, name); };
  for (const char* name : {"x", "y", "z"}) property(name);
  if (fields_.normal) {
    for (const char* name : {"nx", "ny", "nz"}) property(name);
  }
  property("u");
  property("v");
  h += "property uint index\n";
  if (fields_.density) property("density");
  if (fields_.curve_position) property("curve_position");
  if (fields_.face) h += "property uint face\n";
  if (fields_.triangle) h += "property uint triangle\n";
  h += "end_header\n";
  return WriteAll(out_, h);
}

absl::Status SampleWriter::WriteRows(std::FILE* to, const SampleBatch& b) {
  buffer_.clear();
  if (format_ == OutputFormat::kNpy || format_ == OutputFormat::kPlyBinary) {
    PackBinary(b);
    return WriteAll(to, buffer_);
  }
  for (size_t i = 0; i < b.size(); ++i) {
    if (format_ == OutputFormat::kCsv) {
      AppendUint(&buffer_, b.index[i]);
      for (double d : {b.u[i], b.v[i], b.x[i], b.y[i], b.z[i]}) buffer_ += ',', AppendNumber(&buffer_, d);
      if (fields_.normal) {
        for (double d : {b.nx[i], b.ny[i], b.nz[i]}) buffer_ += ',', AppendNumber(&buffer_, d);
      }
      if (fields_.density) buffer_ += ',', AppendNumber(&buffer_, b.density[i]);
      if (fields_.curve_position) buffer_ += ',', AppendNumber(&buffer_, b.curve_position[i]);
      if (fields_.face) buffer_ += ',', AppendUint(&buffer_, b.face[i]);
      if (fields_.triangle) buffer_ += ',', AppendUint(&buffer_, b.triangle[i]);
      buffer_ += '\n';
    } else if (format_ == OutputFormat::kPlyAscii) {
      std::string row;
      for (double d : {b.x[i], b.y[i], b.z[i]}) AppendNumber(&row, d), row += ' ';
      if (fields_.normal) {
        for (double d : {b.nx[i], b.ny[i], b.nz[i]}) AppendNumber(&row, d), row += ' ';
      }
      AppendNumber(&row, b.u[i]), row += ' ';
      AppendNumber(&row, b.v[i]), row += ' ';
      AppendUint(&row, b.index[i]);
      if (fields_.density) row += ' ', AppendNumber(&row, b.density[i]);
      if (fields_.curve_position) row += ' ', AppendNumber(&row, b.curve_position[i]);
      if (fields_.face) row += ' ', AppendUint(&row, b.face[i]);
      if (fields_.triangle) row += ' ', AppendUint(&row, b.triangle[i]);
      buffer_ += row + '\n';
    }
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
  const auto add_real = [&](const std::vector<double>& c) { columns.push_back({c.data(), nullptr, nullptr}); };
  const bool npy = format_ == OutputFormat::kNpy;
  if (npy) columns.push_back({nullptr, b.index.data(), nullptr});
  if (npy) add_real(b.u), add_real(b.v);
  add_real(b.x), add_real(b.y), add_real(b.z);
  if (fields_.normal) add_real(b.nx), add_real(b.ny), add_real(b.nz);
  if (!npy) add_real(b.u), add_real(b.v), columns.push_back({nullptr, b.index.data(), nullptr});
  if (fields_.density) add_real(b.density);
  if (fields_.curve_position) add_real(b.curve_position);
  if (fields_.face) columns.push_back({nullptr, nullptr, b.face.data()});
  if (fields_.triangle) columns.push_back({nullptr, nullptr, b.triangle.data()});
  const size_t index_width = npy ? sizeof(uint64_t) : sizeof(uint32_t);
  size_t record = 0;
  for (const Column& c : columns) record += c.real ? real : c.index ? index_width : sizeof(uint32_t);
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
  if (ply && !batch.index.empty() && batch.index.back() > UINT32_MAX) {
    return absl::InvalidArgumentError("PLY stores the sample index as uint32; use CSV for indices >= 2^32");
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
      if (std::fwrite(buf, 1, n, out_) != n) return absl::UnavailableError("writing the output failed");
    }
  }
  if (std::fflush(out_) != 0) return absl::UnavailableError("flushing the output failed");
  return absl::OkStatus();
}

}  // namespace sfc
