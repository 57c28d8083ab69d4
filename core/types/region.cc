#include "core/types/region.h"

#include <cmath>

#include "absl/strings/str_format.h"

namespace sfc {

absl::Status Region::Validate() const {
  switch (kind) {
    case Kind::kAll:
      return absl::OkStatus();
    case Kind::kParameterRect: {
      const bool finite = std::isfinite(u0) && std::isfinite(u1) && std::isfinite(v0) &&
                          std::isfinite(v1);
      if (!finite || !(u0 < u1) || !(v0 < v1)) {
        return absl::InvalidArgumentError(absl::StrFormat(
            "the parameter rectangle [%g,%g] x [%g,%g] is empty: it needs finite bounds with "
            "u0 < u1 and v0 < v1",
            u0, u1, v0, v1));
      }
      if (u0 < 0 || u1 > 1 || v0 < 0 || v1 > 1) {
        return absl::InvalidArgumentError(absl::StrFormat(
            "the parameter rectangle [%g,%g] x [%g,%g] leaves the unit square [0,1] x [0,1]; "
            "parameters are unit-square coordinates, so it needs 0 <= u0 < u1 <= 1 and "
            "0 <= v0 < v1 <= 1",
            u0, u1, v0, v1));
      }
      return absl::OkStatus();
    }
    case Kind::kBox: {
      if (!IsFinite(lo) || !IsFinite(hi) || !(lo.x < hi.x) || !(lo.y < hi.y) || !(lo.z < hi.z)) {
        return absl::InvalidArgumentError(absl::StrFormat(
            "the box [%g,%g] x [%g,%g] x [%g,%g] is empty: it needs min < max on every axis",
            lo.x, hi.x, lo.y, hi.y, lo.z, hi.z));
      }
      return absl::OkStatus();
    }
  }
  return absl::InvalidArgumentError("unknown region kind");
}

}  // namespace sfc
