// Writes sample batches as CSV, PLY (binary little-endian or ASCII) or NumPy's
// .npy format: every column the request makes, or those --columns names.
//
// CSV starts with the header index,u,v,x,y,z, then the optional columns
// nx,ny,nz, density, curve_position, face, triangle (the last two unsigned
// integers in every format). Numbers are written in the shortest form
// that reads back to the same double (or float, in float32 precision), so
// output is byte-identical for the same samples. PLY has one vertex element
// with x y z (double or float), the optional normals, u v and index (uint32);
// MeshLab and CloudCompare read it. NPY (format 1.0) holds a 1-D structured
// array with the CSV's columns as fields (index '<u8', the rest '<f8' or
// '<f4'): numpy.load(path)['x'].
//
// Thread-compatible: one writer per output.
#ifndef SFCSAMPLER_CLIENT_SAMPLE_WRITER_H_
#define SFCSAMPLER_CLIENT_SAMPLE_WRITER_H_

#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/types/sample_batch.h"
#include "request/stream_options.h"

namespace sfc {

enum class OutputFormat { kCsv, kPlyBinary, kPlyAscii, kNpy };

// Width of the floating-point columns in the file: the same type as a
// stream's (request/stream_options.h). Float32 rounds each double to the
// nearest float (as the wire's PRECISION_FLOAT32 does), so a float32 file is
// the same from a float64 or a float32 stream.
using OutputPrecision = ColumnPrecision;

class SampleWriter {
 public:
  // Opens `path` ("-" = stdout). `expected_count` is the exact number of
  // samples when known; PLY output without it is staged in a temporary file
  // so the header can carry the count (likewise NPY).
  // `columns`: the names of the columns to write (--columns; empty = every
  // column the fields make), each in the format's own order.
  static absl::StatusOr<std::unique_ptr<SampleWriter>> Open(
      const std::string& path, OutputFormat format, const SampleFields& fields,
      std::optional<uint64_t> expected_count, OutputPrecision precision = OutputPrecision::kFloat64,
      const std::vector<std::string>& columns = {});
  // Open's check of `columns` alone, before any sampling: INVALID_ARGUMENT
  // for an unknown name, a column the fields do not make (naming its flag),
  // or PLY without x, y and z.
  static absl::Status CheckColumns(OutputFormat format, const SampleFields& fields,
                                   const std::vector<std::string>& columns);
  // The fields to ask a sample source for when only `columns` are written
  // (empty: `fields` unchanged): the float columns no named column needs are
  // left off, u v and x y z included, so they are neither made nor sent. If
  // no float column would remain, u and v stay (the wire needs one). face and
  // triangle stay as asked, so a surface without them is still refused.
  // REQUIRES: CheckColumns(format, fields, columns) passed.
  static SampleFields SourceFields(SampleFields fields, const std::vector<std::string>& columns);
  ~SampleWriter();

  absl::Status Write(const SampleBatch& batch);
  // Completes the file. REQUIRES: called once, after the last Write.
  absl::Status Finish();

  uint64_t written() const { return written_; }

 private:
  SampleWriter(std::FILE* out, bool owns, OutputFormat format, const SampleFields& fields,
               OutputPrecision precision);
  absl::Status WriteHeader(uint64_t count);
  absl::Status WriteRows(std::FILE* to, const SampleBatch& batch);
  // The batch's records in NPY or binary PLY, into buffer_.
  void PackBinary(const SampleBatch& batch);
  std::string NpyHeader(uint64_t count) const;
  void AppendNumber(std::string* out, double value) const;  // shortest text

  std::FILE* out_;
  bool owns_;
  std::FILE* staging_ = nullptr;  // PLY with unknown count
  OutputFormat format_;
  SampleFields fields_;
  OutputPrecision precision_;
  std::optional<uint64_t> expected_;
  uint64_t written_ = 0;
  std::string buffer_;
  std::vector<int> layout_;  // the file's columns in its order (sample_writer.cc's Col)
};

}  // namespace sfc

#endif  // SFCSAMPLER_CLIENT_SAMPLE_WRITER_H_
