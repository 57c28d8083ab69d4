// Writes sample batches as CSV or PLY (binary little-endian or ASCII).
//
// CSV starts with the header index,u,v,x,y,z, then the optional columns
// nx,ny,nz, density, curve_position. Numbers are written in the shortest form
// that reads back to the same double, so output is byte-identical for the
// same samples. PLY has one vertex element with x y z (double), the optional
// normals, u v (double) and index (uint32); MeshLab and CloudCompare read it.
//
// Thread-compatible: one writer per output.
#ifndef SFCSAMPLER_CLIENT_SAMPLE_WRITER_H_
#define SFCSAMPLER_CLIENT_SAMPLE_WRITER_H_

#include <cstdio>
#include <memory>
#include <optional>
#include <string>

#include "absl/status/statusor.h"
#include "core/sample_batch.h"

namespace sfc {

enum class OutputFormat { kCsv, kPlyBinary, kPlyAscii };

class SampleWriter {
 public:
  // Opens `path` ("-" = stdout). `expected_count` is the exact number of
  // samples when known; PLY output without it is staged in a temporary file
  // so the header can carry the count.
  static absl::StatusOr<std::unique_ptr<SampleWriter>> Open(const std::string& path,
                                                            OutputFormat format,
                                                            const SampleFields& fields,
                                                            std::optional<uint64_t> expected_count);
  ~SampleWriter();

  absl::Status Write(const SampleBatch& batch);
  // Completes the file. REQUIRES: called once, after the last Write.
  absl::Status Finish();

  uint64_t written() const { return written_; }

 private:
  SampleWriter(std::FILE* out, bool owns, OutputFormat format, const SampleFields& fields);
  absl::Status WriteHeader(uint64_t count);
  absl::Status WriteRows(std::FILE* to, const SampleBatch& batch);

  std::FILE* out_;
  bool owns_;
  std::FILE* staging_ = nullptr;  // PLY with unknown count
  OutputFormat format_;
  SampleFields fields_;
  std::optional<uint64_t> expected_;
  uint64_t written_ = 0;
  std::string buffer_;
};

}  // namespace sfc

#endif  // SFCSAMPLER_CLIENT_SAMPLE_WRITER_H_
