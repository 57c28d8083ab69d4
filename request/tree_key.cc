#include "request/tree_key.h"

#include "absl/strings/str_format.h"
#include "request/sample_request.h"

namespace sfc {

uint64_t Fnv1a64(const std::string& text) {
  uint64_t h = 0xcbf29ce484222325ULL;
  for (unsigned char c : text) {
    h ^= c;
    h *= 0x100000001b3ULL;
  }
  return h;
}

std::string TreeKey::Hex() const { return absl::StrFormat("%016x", hash); }

std::string TreeKey::HexWithGrade(int grade) const {
  return absl::StrFormat("%016x-g%d", hash, grade);
}

TreeKey MakeTreeKey(const std::string& canonical_surface, const std::string& canonical_density,
                    const CurveTreeOptions& options) {
  TreeKey key;
  // The algorithm version is part of the key: a tree of another version is
  // another tree, in every cache and behind the proxy's hash.
  key.canonical = absl::StrFormat(
      "version=%s|surface=%s|density=%s|curve=%s|estimator=%s|tolerance=%.17g|depth_cap=%d|rho=%."
      "17g",
      kAlgorithmVersion, canonical_surface, canonical_density, CurveName(options.curve),
      AreaEstimatorName(options.estimator), options.tolerance, options.depth_cap, options.rho);
  key.hash = Fnv1a64(key.canonical);
  return key;
}

}  // namespace sfc
