// Regions of interest for locality-aware requests: a parameter rectangle or
// an axis-aligned 3D box, both closed. Value type; thread-compatible.
#ifndef SFCSAMPLER_CORE_TYPES_REGION_H_
#define SFCSAMPLER_CORE_TYPES_REGION_H_

#include "absl/status/status.h"
#include "core/types/vec3.h"

namespace sfc {

struct Region {
  enum class Kind { kAll, kParameterRect, kBox };
  Kind kind = Kind::kAll;
  double u0 = 0, u1 = 1, v0 = 0, v1 = 1;  // kParameterRect: [u0,u1] x [v0,v1] in the unit square
  Vec3 lo, hi;                            // kBox: [lo, hi] per axis, surface units

  static Region ParameterRect(double u0, double u1, double v0, double v1) {
    Region r;
    r.kind = Kind::kParameterRect;
    r.u0 = u0, r.u1 = u1, r.v0 = v0, r.v1 = v1;
    return r;
  }
  static Region Box(const Vec3& lo, const Vec3& hi) {
    Region r;
    r.kind = Kind::kBox;
    r.lo = lo, r.hi = hi;
    return r;
  }

  bool Contains(double u, double v, const Vec3& p) const {
    switch (kind) {
      case Kind::kAll:
        return true;
      case Kind::kParameterRect:
        return u >= u0 && u <= u1 && v >= v0 && v <= v1;
      case Kind::kBox:
        return p.x >= lo.x && p.x <= hi.x && p.y >= lo.y && p.y <= hi.y && p.z >= lo.z &&
               p.z <= hi.z;
    }
    return false;
  }

  // INVALID_ARGUMENT for an empty or degenerate region (zero area or volume,
  // or non-finite bounds) and for a parameter rectangle that is not inside
  // the unit square.
  absl::Status Validate() const;
};

}  // namespace sfc

#endif  // SFCSAMPLER_CORE_TYPES_REGION_H_
