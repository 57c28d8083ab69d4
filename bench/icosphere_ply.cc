// Writes the subdivided icosahedron (mesh/icosphere.h) as binary PLY: the
// sphere mesh of `sfcsampler eval --mesh-sphere` and bench/eval_quality.sh.
// Usage: icosphere_ply FILE [SUBDIVISIONS=6 (81 920 triangles)]
#include <cstdio>
#include <fstream>
#include <string>

#include "mesh/icosphere.h"
#include "mesh/mesh_writer.h"

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s FILE [SUBDIVISIONS]\n", argv[0]);
    return 2;
  }
  const int subdivisions = argc > 2 ? std::stoi(argv[2]) : 6;
  const sfc::TriangleMesh mesh = sfc::MakeIcosphere(subdivisions);
  std::ofstream(argv[1], std::ios::binary) << sfc::MeshToPly(mesh, /*binary=*/true);
  std::printf("%s: %zu triangles\n", argv[1], mesh.triangles.size());
  return 0;
}
