// The body of the CAD model fuzz targets (STEP, IGES, NURBS): the bytes go
// through cad::Load (preflight, OpenCASCADE's reader, the face census, face
// construction) with a time budget; a refusal is checked as fuzz/model_fuzz.h
// says, and an accepted model must have at least one face, each with a finite
// area.
#ifndef SFCSAMPLER_FUZZ_CAD_MODEL_FUZZ_H_
#define SFCSAMPLER_FUZZ_CAD_MODEL_FUZZ_H_

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

#include "cad/load.h"
#include "fuzz/model_fuzz.h"

namespace sfc::fuzz {

inline int FuzzCadModel(ModelFormat format, const char* name, const uint8_t* data, size_t size) {
  RememberInput(data, size);
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  cad::LoadOptions options;
  options.check = Budget(2.0);
  auto model = cad::Load(format, bytes, name, options);
  if (!model.ok()) {
    CheckRefusal(model.status());
    return 0;
  }
  if ((*model)->faces().empty()) Fail("a model without faces was accepted", {});
  for (const auto& face : (*model)->faces()) {
    if (!std::isfinite(face.area())) Fail("a face with a non-finite area", {});
  }
  return 0;
}

}  // namespace sfc::fuzz

#endif  // SFCSAMPLER_FUZZ_CAD_MODEL_FUZZ_H_
