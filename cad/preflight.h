// Preflight of STEP and IGES text: a linear scan, before OpenCASCADE sees the
// bytes, that refuses what its readers cannot survive and takes the census
// that Load checks the reader's result against.
//
// Why: OpenCASCADE's StepData reader recurses once per nested parenthesis
// (StepData_UndefinedEntity::ReadRecord), about 128 bytes of stack a level: a
// STEP whose DATA nests 65 000 deep overflows an 8 MiB thread stack (16 000
// deep a 2 MiB one) and kills the process (measured with OCC 7.6, see
// README "CAD models"). Real files nest at most 4-5 deep (a B-spline
// surface's lists of lists), so the default limit of 64 leaves both real
// files and the stack a wide margin.
//
// Thread-safety: pure functions.
#ifndef SFCSAMPLER_CAD_PREFLIGHT_H_
#define SFCSAMPLER_CAD_PREFLIGHT_H_

#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"

namespace sfc::cad {

struct PreflightLimits {
  // Deepest parenthesis nesting in a STEP record. Default 64 (real files:
  // <= 5; OCC 7.6 overflows a 2 MiB stack near 16 000).
  int max_nesting = 64;
  // Most entity instances (STEP #N = ... records; IGES directory entries).
  // Default 4 000 000 (the reader keeps ~1 KB for each).
  uint64_t max_entities = 4'000'000;
  // Longest STEP record (one entity instance, from '#' to ';') in bytes.
  // Default 16 MiB (a 1000 x 1000 B-spline control net takes ~10 MB).
  uint64_t max_record_bytes = uint64_t{16} << 20;
  // Longest IGES line, in characters before the line end. IGES records are
  // 80 columns; default 80.
  uint64_t max_iges_line = 80;
};

// What a file declares, for the comparison after the read.
struct ModelCensus {
  uint64_t entities = 0;
  int max_nesting = 0;
  uint64_t longest_record = 0;
  // The face entities of the file, each named as the reader's messages and
  // users name it: "#12 ADVANCED_FACE" (STEP), "DE 37 type 144" (IGES).
  std::vector<std::string> faces;
  // Their ids: STEP entity numbers, IGES directory sequence numbers.
  std::vector<uint64_t> face_ids;
};

// STEP (ISO 10303-21): strings and comments are read as OpenCASCADE's lexer
// reads them and skipped; every record is measured and its parentheses must
// balance, and every entity instance name ("#N =") must be defined once and
// fit an int, as the reader keeps it. Faces are ADVANCED_FACE and
// FACE_SURFACE instances (ORIENTED_FACE only reuses another face).
// INVALID_ARGUMENT, with the limit's name (or the names at fault), where it
// was hit and what to fix.
absl::StatusOr<ModelCensus> PreflightStep(absl::string_view bytes, const PreflightLimits& limits);

// IGES (fixed 80-column records): line lengths and directory entries. Faces
// are entities of type 510 (face), 144 (trimmed surface) and 143 (bounded
// surface), and untrimmed surfaces (128, 114, 118, 120, 122, 140, 190-198)
// whose directory entry marks them independent (subordinate switch 00).
absl::StatusOr<ModelCensus> PreflightIges(absl::string_view bytes, const PreflightLimits& limits);

}  // namespace sfc::cad

#endif  // SFCSAMPLER_CAD_PREFLIGHT_H_
