// The body of the mesh fuzz targets (OBJ, PLY): the bytes go through
// LoadMesh (the line scan, the reader, FinalizeMesh) with a time budget; a
// refusal is checked as fuzz/model_fuzz.h says, and an accepted mesh must
// index only its own vertices.
#ifndef SFCSAMPLER_FUZZ_MESH_FUZZ_H_
#define SFCSAMPLER_FUZZ_MESH_FUZZ_H_

#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz/model_fuzz.h"
#include "mesh/mesh_loader.h"

namespace sfc::fuzz {

inline int FuzzMesh(ModelFormat format, const char* name, const uint8_t* data, size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  MeshLoadOptions options;
  options.format = format;
  options.check = Budget(2.0);
  auto mesh = LoadMesh(bytes, name, options);
  if (!mesh.ok()) {
    CheckRefusal(mesh.status());
    return 0;
  }
  for (const auto& t : mesh->triangles) {
    for (uint32_t v : t) {
      if (v >= mesh->positions.size()) Fail("a triangle past the vertices", {});
    }
  }
  return 0;
}

}  // namespace sfc::fuzz

#endif  // SFCSAMPLER_FUZZ_MESH_FUZZ_H_
