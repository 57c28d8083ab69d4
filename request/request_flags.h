// Command-line flags that describe a sampling request, shared by the CLI's
// subcommands, and their conversion into a SampleRequest.
#ifndef SFCSAMPLER_REQUEST_REQUEST_FLAGS_H_
#define SFCSAMPLER_REQUEST_REQUEST_FLAGS_H_

#include <string>

#include "CLI/CLI.hpp"
#include "absl/status/statusor.h"
#include "request/sample_request.h"

namespace sfc {

struct RequestFlags {
  std::string surface = "sphere";
  std::string density = "uniform";
  std::string curve = "hilbert";
  std::string estimator = "fff";
  std::string sequence = "jittered";
  double tolerance = 0;
  int depth_cap = 0;
  double rho = 1.0;
  uint64_t count = 10000;
  uint64_t seed = 1;
  uint64_t tree_count = 0;
  uint64_t begin = 0, end = 0;
  std::string shard;   // "i/K"
  std::string region;  // "uv:U0,U1,V0,V1" or "box:X0,Y0,Z0,X1,Y1,Z1"
  bool normals = false, density_column = false, curve_position = false;
  bool face = false, triangle = false;
};

// Checks a uint64_t flag as typed: a whole number from 0 to 2^64 - 1, else
// an error quoting it (CLI11 alone saturates -1 and 2^64 to 2^64 - 1).
extern const CLI::Validator kWholeNumber;

// Adds the tree-shaping flags (surface, density, curve, ...) to `cmd`.
void AddTreeFlags(CLI::App* cmd, RequestFlags* flags);
// Adds the set-selection flags (count, seed, sequence, range, shard, region, columns).
void AddSampleFlags(CLI::App* cmd, RequestFlags* flags);

// INVALID_ARGUMENT naming the flag for unknown names or malformed values.
absl::StatusOr<TreeSpec> ToTreeSpec(const RequestFlags& flags);
absl::StatusOr<SampleRequest> ToSampleRequest(const RequestFlags& flags);

}  // namespace sfc

#endif  // SFCSAMPLER_REQUEST_REQUEST_FLAGS_H_
