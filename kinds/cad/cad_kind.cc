#include "kinds/cad/cad_kind.h"

#include "kinds/module_kind.h"

namespace sfc {

std::unique_ptr<const SurfaceKind> MakeCadKind() {
  return MakeModuleKind(CadKindInfo(), "libsfcsampler-cad.so", "sfcsampler_make_cad_kind");
}

}  // namespace sfc
