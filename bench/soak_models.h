// The models of the soak's model phase (bench/load_generator): good ones
// written to files (the CAD fixtures as STEP, IGES and NURBS; icospheres of
// several sizes as OBJ and PLY), large meshes that push the server's
// parsed-model budget, and hostile uploads a server must refuse (deep STEP
// nesting, a shell listing one face many times, out-of-range OBJ indices, a
// PLY header declaring a billion vertices, truncated files, an empty upload).
//
// Thread-safety: Write() touches OpenCASCADE's global state: call it from one
// thread. After that the object is immutable and Hostile() is thread-safe
// (it takes the caller's random generator).
#ifndef SFCSAMPLER_BENCH_SOAK_MODELS_H_
#define SFCSAMPLER_BENCH_SOAK_MODELS_H_

#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "absl/status/statusor.h"

namespace sfc {

struct SoakModel {
  std::string spec;  // "FORMAT:PATH", what a client samples
  std::string format;
  uint64_t bytes = 0;
  bool cad = false;  // has faces (CAD) rather than triangles (mesh)
};

struct HostileUpload {
  std::string format, name, bytes;
  std::string what;  // for the table: "nested parentheses", ...
};

class SoakModels {
 public:
  // Writes the good and large models into `dir` (which must exist). Large
  // meshes are icospheres of `large_subdivisions` (8: 1.3 M triangles).
  static absl::StatusOr<SoakModels> Write(const std::string& dir, int large_subdivisions);

  const std::vector<SoakModel>& good() const { return good_; }
  const std::vector<SoakModel>& large() const { return large_; }

  // A hostile upload; `rng` varies its bytes, so that most are new to the
  // server (a remembered failure is cheap) and some repeat.
  HostileUpload Hostile(std::mt19937_64& rng) const;

 private:
  std::vector<SoakModel> good_, large_;
  std::string sphere_step_, box_step_, box_iges_, small_ply_;
};

}  // namespace sfc

#endif  // SFCSAMPLER_BENCH_SOAK_MODELS_H_
