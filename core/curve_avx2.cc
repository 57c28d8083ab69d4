// Built with -O3 -mavx2 (core/CMakeLists.txt): hilbert_batch::Descend
// vectorised 4 strings at a time. Integer work only, so its bits are the
// scalar code's.
#include "core/hilbert_batch.h"

namespace sfc::hilbert_batch {

void DescendAvx2(const Masks& m, const uint64_t* digits, int levels, size_t n, uint64_t* states,
                 uint64_t* xs, uint64_t* ys) {
  Descend(m, digits, levels, n, states, xs, ys);
}

}  // namespace sfc::hilbert_batch
