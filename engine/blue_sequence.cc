#include "engine/blue_sequence.h"

#include <memory>
#include <vector>

#include "base/status_macros.h"
#include "core/blue_relaxation.h"

namespace sfc {

absl::StatusOr<Sequence> BlueSequence(const TreeLookup& lookup, const CursorOpener& open,
                                      uint64_t count, uint64_t seed, int threads,
                                      const BuildControl& caller) {
  // Mass coordinates are placed as a sequence of their own: in-leaf placement
  // depends on the mass coordinate and the tree only, never on the count, so
  // a candidate lands where the same q of the final sequence does.
  const MassPlacer place = [&](const double* q, size_t n, Vec3* p,
                               double* density) -> absl::Status {
    CursorSpec spec;
    spec.begin = 0, spec.end = n;
    spec.fields.density = density != nullptr;
    spec.threads = 1;
    ASSIGN_OR_RETURN(
        std::unique_ptr<BatchCursor> cursor,
        open(lookup, Sequence::FromTable(std::make_shared<std::vector<double>>(q, q + n), seed),
             spec));
    SampleBatch batch;
    while (batch.size() < n) {
      ASSIGN_OR_RETURN(const size_t got, cursor->Next(n - batch.size(), &batch));
      if (got == 0) break;
    }
    if (batch.size() != n) {
      return absl::InternalError("a cursor placed fewer mass coordinates than it was given");
    }
    for (size_t i = 0; i < n; ++i) {
      p[i] = {batch.x[i], batch.y[i], batch.z[i]};
      if (density) density[i] = batch.density[i];
    }
    return absl::OkStatus();
  };
  BlueNoiseOptions options;
  options.check = caller.check;
  ASSIGN_OR_RETURN(const BlueNoiseSet set,
                   RelaxBlueNoise(count, seed, lookup.any->total_mass(), place, threads, options));
  return Sequence::FromTable(set.q, seed);
}

}  // namespace sfc
