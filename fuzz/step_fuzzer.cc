// libFuzzer target: STEP models through cad::Load (fuzz/cad_model_fuzz.h).
#include "fuzz/cad_model_fuzz.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return sfc::fuzz::FuzzCadModel(sfc::ModelFormat::kStep, "fuzz.step", data, size);
}
