// CAD models (step:FILE, iges:FILE, nurbs:FILE or FORMAT:sha256=HEX) through
// cad/: one tree per face, one curve through all faces
// (cad/model_sampler.h), a cursor with the face column, and the faces as a
// table (sfcsampler inspect).
//
// Densities are the catalogue's (core/density.h): uniform, gaussian, mean
// (from the kernel's exact second derivatives) and expr: in u, v (the face's
// own unit square) and x, y, z.
//
// The kind's code is the module libsfcsampler-cad.so (kinds/cad/cad_module.cc),
// loaded when a request first names a CAD model (kinds/module_kind.h), so
// that programs load OpenCASCADE only when they read a model.
#ifndef SFCSAMPLER_KINDS_CAD_CAD_KIND_H_
#define SFCSAMPLER_KINDS_CAD_CAD_KIND_H_

#include <memory>

#include "engine/surface_kind.h"

namespace sfc {

// The registry's CAD kind: the module's, loaded on first use.
std::unique_ptr<const SurfaceKind> MakeCadKind();

// What the CAD kind is; the same in the program and in the module.
const KindInfo& CadKindInfo();

}  // namespace sfc

#endif  // SFCSAMPLER_KINDS_CAD_CAD_KIND_H_
