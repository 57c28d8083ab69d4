// Built with -mavx512f -ffp-contract=off (core/CMakeLists.txt): the sobol
// points eight lanes to a vector (core/sequence_internal.h), the scalar
// code's integer steps in each lane.
#include <cstring>

#include "base/counter_hash.h"
#include "core/sequence_internal.h"

namespace sfc::sequence_internal {

size_t PointsOnAvx512(const uint32_t* ks, uint64_t k0, size_t n, const ScrambleTables& table,
                      double* a, double* b) {
  size_t i = 0;
  for (; i + 8 <= n; i += 8) {
    U64x8 k;
    for (int j = 0; j < 8; ++j) k[j] = ks != nullptr ? ks[i + j] : k0 + i + j;
    const U64x8 k_mix = CounterMix(k);
    const F64x8 va = LinearScramble(k, k_mix, 0, table);
    const F64x8 vb = LinearScramble(k, k_mix, 1, table);
    std::memcpy(a + i, &va, sizeof(va));
    std::memcpy(b + i, &vb, sizeof(vb));
  }
  return i;
}

}  // namespace sfc::sequence_internal
