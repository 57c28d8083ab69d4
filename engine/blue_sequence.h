// The blue-noise sequence of a request (docs/ALGORITHM.md, "Blue noise"):
// core's stratum-constrained relaxation (core/blue_relaxation.h) run on the
// prepared tree, with the tree's own kind placing the candidates through its
// cursor (engine/surface_kind.h), so formula surfaces, CAD models and meshes
// get it alike and a blue sample lies exactly where the relaxation put it.
//
// Thread-safety: BlueSequence is reentrant.
#ifndef SFCSAMPLER_ENGINE_BLUE_SEQUENCE_H_
#define SFCSAMPLER_ENGINE_BLUE_SEQUENCE_H_

#include <cstdint>

#include "absl/status/statusor.h"
#include "core/sequence.h"
#include "engine/surface_kind.h"
#include "engine/tree_source.h"

namespace sfc {

// The kBlue sequence of `count` samples of `seed` on the tree `lookup`, whose
// kind opens cursors with `open`; computed whole with `threads` threads (the
// bytes do not depend on them). Errors: the cursor's (INVALID_ARGUMENT when
// the surface or density is not usable at a sample); caller.check's non-OK
// status (client gone, deadline), which it asks at least every few tens of
// milliseconds of the relaxation (BlueNoiseOptions::check).
absl::StatusOr<Sequence> BlueSequence(const TreeLookup& lookup, const CursorOpener& open,
                                      uint64_t count, uint64_t seed, int threads,
                                      const BuildControl& caller = {});

}  // namespace sfc

#endif  // SFCSAMPLER_ENGINE_BLUE_SEQUENCE_H_
