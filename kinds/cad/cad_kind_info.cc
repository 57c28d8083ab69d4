#include "kinds/cad/cad_kind.h"

namespace sfc {

const KindInfo& CadKindInfo() {
  static const KindInfo* const info = new KindInfo{
      "model", "a CAD model surface (step:, iges: or nurbs:)",
      {ModelFormat::kStep, ModelFormat::kIges, ModelFormat::kNurbs},
      /*face_column=*/true, /*triangle_column=*/false, /*describes=*/true};
  return *info;
}

}  // namespace sfc
