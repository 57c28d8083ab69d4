#include "client/sample_writer.h"

#include <charconv>
#include <cstring>

#include "absl/strings/str_format.h"
#include "core/status_macros.h"

namespace sfc {
namespace {

void AppendDouble(std::string* out, double value) {
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

SampleWriter::SampleWriter(std::FILE* out, bool owns, OutputFormat format, const SampleFields& fields)
    : out_(out), owns_(owns), format_(format), fields_(fields) {}

SampleWriter::~SampleWriter() {
  if (staging_) std::fclose(staging_);
  if (owns_ && out_) std::fclose(out_);
}

absl::StatusOr<std::unique_ptr<SampleWriter>> SampleWriter::Open(
    const std::string& path, OutputFormat format, const SampleFields& fields,
    std::optional<uint64_t> expected_count) {
  std::FILE* f = path == "-" ? stdout : std::fopen(path.c_str(), "wb");
  if (!f) {
    return absl::InvalidArgumentError(
        absl::StrFormat("cannot open \"%s\" for writing: %s", path, std::strerror(errno)));
  }
  auto writer = std::unique_ptr<SampleWriter>(new SampleWriter(f, path != "-", format, fields));
  writer->expected_ = expected_count;
  if (format == OutputFormat::kCsv) {
    RETURN_IF_ERROR(writer->WriteHeader(0));
  } else if (expected_count) {
    RETURN_IF_ERROR(writer->WriteHeader(*expected_count));
  } else {
    writer->staging_ = std::tmpfile();
    if (!writer->staging_) return absl::InternalError("cannot create a temporary file for PLY output");
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
    h += "\n";
    return WriteAll(out_, h);
  }
  h = "ply\n";
  h += format_ == OutputFormat::kPlyAscii ? "format ascii 1.0\n" : "format binary_little_endian 1.0\n";
  h += "comment sfcsampler samples in curve order\n";
  h += absl::StrFormat("element vertex %d\n", count);
  h += "property double x\nproperty double y\nproperty double z\n";
  if (fields_.normal) h += "property double nx\nproperty double ny\nproperty double nz\n";
  h += "property double u\nproperty double v\nproperty uint index\n";
  if (fields_.density) h += "property double density\n";
  if (fields_.curve_position) h += "property double curve_position\n";
  h += "end_header\n";
  return WriteAll(out_, h);
}

absl::Status SampleWriter::WriteRows(std::FILE* to, const SampleBatch& b) {
  buffer_.clear();
  for (size_t i = 0; i < b.size(); ++i) {
    if (format_ == OutputFormat::kCsv) {
      AppendUint(&buffer_, b.index[i]);
      for (double d : {b.u[i], b.v[i], b.x[i], b.y[i], b.z[i]}) buffer_ += ',', AppendDouble(&buffer_, d);
      if (fields_.normal) {
        for (double d : {b.nx[i], b.ny[i], b.nz[i]}) buffer_ += ',', AppendDouble(&buffer_, d);
      }
      if (fields_.density) buffer_ += ',', AppendDouble(&buffer_, b.density[i]);
      if (fields_.curve_position) buffer_ += ',', AppendDouble(&buffer_, b.curve_position[i]);
      buffer_ += '\n';
    } else if (format_ == OutputFormat::kPlyAscii) {
      std::string row;
      for (double d : {b.x[i], b.y[i], b.z[i]}) AppendDouble(&row, d), row += ' ';
      if (fields_.normal) {
        for (double d : {b.nx[i], b.ny[i], b.nz[i]}) AppendDouble(&row, d), row += ' ';
      }
      AppendDouble(&row, b.u[i]), row += ' ';
      AppendDouble(&row, b.v[i]), row += ' ';
      AppendUint(&row, b.index[i]);
      if (fields_.density) row += ' ', AppendDouble(&row, b.density[i]);
      if (fields_.curve_position) row += ' ', AppendDouble(&row, b.curve_position[i]);
      buffer_ += row + '\n';
    } else {
      for (double d : {b.x[i], b.y[i], b.z[i]}) AppendBinary(&buffer_, d);
      if (fields_.normal) {
        for (double d : {b.nx[i], b.ny[i], b.nz[i]}) AppendBinary(&buffer_, d);
      }
      AppendBinary(&buffer_, b.u[i]);
      AppendBinary(&buffer_, b.v[i]);
      AppendBinary(&buffer_, static_cast<uint32_t>(b.index[i]));
      if (fields_.density) AppendBinary(&buffer_, b.density[i]);
      if (fields_.curve_position) AppendBinary(&buffer_, b.curve_position[i]);
    }
  }
  return WriteAll(to, buffer_);
}

absl::Status SampleWriter::Write(const SampleBatch& batch) {
  if (format_ != OutputFormat::kCsv && !batch.index.empty() && batch.index.back() > UINT32_MAX) {
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
