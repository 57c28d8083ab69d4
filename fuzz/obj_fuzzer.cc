// libFuzzer target: OBJ meshes through LoadMesh (fuzz/mesh_fuzz.h).
#include "fuzz/mesh_fuzz.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return sfc::fuzz::FuzzMesh(sfc::ModelFormat::kObj, "fuzz.obj", data, size);
}
