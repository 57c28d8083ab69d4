// libFuzzer target: STEP models through cad::Load (preflight, OpenCASCADE's
// reader, the face census, face construction). See fuzz/model_fuzz.h for
// what is checked; an accepted model must have at least one face, each with
// a finite, positive area.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

#include "cad/load.h"
#include "fuzz/model_fuzz.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  sfc::fuzz::RememberInput(data, size);
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  sfc::cad::LoadOptions options;
  options.check = sfc::fuzz::Budget(2.0);
  auto model = sfc::cad::Load(sfc::cad::ModelFormat::kStep, bytes, "fuzz.step", options);
  if (!model.ok()) {
    sfc::fuzz::CheckRefusal(model.status());
    return 0;
  }
  if ((*model)->faces().empty()) sfc::fuzz::Fail("a model without faces was accepted", {});
  for (const auto& face : (*model)->faces()) {
    if (!std::isfinite(face.area())) sfc::fuzz::Fail("a face with a non-finite area", {});
  }
  return 0;
}
