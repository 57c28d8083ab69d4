// Formula surfaces: the catalogue's surfaces and expr: surfaces in u, v with
// the catalogue's densities (catalog/catalog.h), sampled by core's Sampler on
// a CurveTree. The specs that name no model file.
#ifndef SFCSAMPLER_KINDS_FORMULA_FORMULA_KIND_H_
#define SFCSAMPLER_KINDS_FORMULA_FORMULA_KIND_H_

#include <memory>

#include "engine/surface_kind.h"

namespace sfc {

std::unique_ptr<const SurfaceKind> MakeFormulaKind();

}  // namespace sfc

#endif  // SFCSAMPLER_KINDS_FORMULA_FORMULA_KIND_H_
