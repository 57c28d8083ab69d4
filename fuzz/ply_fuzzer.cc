// libFuzzer target: PLY meshes through LoadMesh (fuzz/mesh_fuzz.h).
#include "fuzz/mesh_fuzz.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return sfc::fuzz::FuzzMesh(sfc::ModelFormat::kPly, "fuzz.ply", data, size);
}
