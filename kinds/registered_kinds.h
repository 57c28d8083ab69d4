// The kinds of surface this build has (kinds/CMakeLists.txt lists them, one
// line each), for SamplingEngine. Thread-safe; lives for the whole program.
#ifndef SFCSAMPLER_KINDS_REGISTERED_KINDS_H_
#define SFCSAMPLER_KINDS_REGISTERED_KINDS_H_

#include "engine/surface_kind.h"

namespace sfc {

const SurfaceKinds& RegisteredSurfaceKinds();

}  // namespace sfc

#endif  // SFCSAMPLER_KINDS_REGISTERED_KINDS_H_
