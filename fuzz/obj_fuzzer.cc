// libFuzzer target: OBJ meshes through LoadMesh (the line scan, the
// reader, FinalizeMesh). See fuzz/model_fuzz.h for what is checked; an
// accepted mesh must index only its own vertices.
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz/model_fuzz.h"
#include "mesh/mesh_loader.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  sfc::MeshLoadOptions options;
  options.format = sfc::MeshFormat::kObj;
  options.check = sfc::fuzz::Budget(2.0);
  auto mesh = sfc::LoadMesh(bytes, "fuzz.obj", options);
  if (!mesh.ok()) {
    sfc::fuzz::CheckRefusal(mesh.status());
    return 0;
  }
  for (const auto& t : mesh->triangles) {
    for (uint32_t v : t) {
      if (v >= mesh->positions.size()) sfc::fuzz::Fail("a triangle past the vertices", {});
    }
  }
  return 0;
}
