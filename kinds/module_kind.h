// A kind of surface whose code lives in a shared module, loaded on first use.
// The registry (kinds/registered_kinds.h) holds this proxy, which answers
// info() without the module; Resolve and Describe load it once (dlopen,
// RTLD_NOW | RTLD_LOCAL, never unloaded) and forward to the kind it makes.
// Why: OpenCASCADE's 18 libraries cost every run of a program that links them
// ~22 ms of dynamic linking, whatever it samples (docs/MEASURED.md); a run
// that reads no CAD model now never loads them.
//
// The module is the file `file`, looked for in this order, first found wins:
//   1. $SFCSAMPLER_LIB_DIR/
//   2. the folder of the binary that holds this code (the Python package's
//      folder, where _core.so is);
//   3. that folder's ../lib/sfcsampler/ (an installed bin/ next to lib/);
//   4. the build tree's lib/sfcsampler/ (compiled in).
// It exports `factory` (extern "C" SurfaceKind* (WorkerPool* the program's
// pool, which the module's cursors then share: base/worker_pool.h) and
// sfcsampler_kind_module_abi (extern "C" const char* ()), which must equal
// KindModuleAbi(): a module of another build is refused.
//
// Errors from Resolve and Describe when the module cannot be used:
// FAILED_PRECONDITION naming the file, where it was looked for and what to set.
// The first file found is the one used (one that fails to load ends the
// search), and a failed load is remembered for the life of the process.
//
// Thread-safety: as every kind, immutable after the first load; the load is
// once for all threads.
#ifndef SFCSAMPLER_KINDS_MODULE_KIND_H_
#define SFCSAMPLER_KINDS_MODULE_KIND_H_

#include <memory>
#include <string>

#include "engine/surface_kind.h"

namespace sfc {

std::unique_ptr<const SurfaceKind> MakeModuleKind(const KindInfo& info, std::string file,
                                                  std::string factory);

// The stamp a kind module and its host compare: the algorithm version, the
// build tree's identity (a random id made when the tree is first
// configured) and the sizes of the types that cross between them.
std::string KindModuleAbi();

}  // namespace sfc

#endif  // SFCSAMPLER_KINDS_MODULE_KIND_H_
