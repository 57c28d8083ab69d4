// Built with -mavx512f -ffp-contract=off (core/CMakeLists.txt): the tree warp's
// vector loops (core/tree_warp_lanes.h) for AVX-512F (the kAvx512 path); each lane the scalar
// code's IEEE operations and integer look-ups, so their bits are the scalar
// path's.
#include "core/tree_warp_lanes.h"

namespace sfc::tree_warp_internal {

size_t DescendGrid2Avx512(size_t m, double* a, double* b, int32_t* ref, uint8_t* state,
                          const double* splits, const int32_t* children, const int32_t* state_at) {
  return DescendGrid2Lanes(m, a, b, ref, state, splits, children, state_at);
}

size_t DigitsGrid2Avx512(size_t m, const double* x, const double* y, const uint8_t* state,
                         double cells, uint64_t top, int chunks, int head, const int32_t* child_at,
                         const int32_t* state_at, const uint64_t* encode, uint64_t* digits) {
  return DigitsGrid2Lanes(m, x, y, state, cells, top, chunks, head, child_at, state_at, encode,
                          digits);
}

void InvertCdfsAvx512(size_t n, const uint8_t* lanes, const double (*p)[3], const double* share,
                      double* out) {
  InvertCdfsLanes(n, lanes, p, share, out);
}

}  // namespace sfc::tree_warp_internal
