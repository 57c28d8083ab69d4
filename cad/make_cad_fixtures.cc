// make_cad_fixtures DIR: writes the project's CAD test models (cad/fixtures.h)
// into DIR: a sphere, a cylinder and a box with a fillet and a through hole as
// STEP and IGES, and a NURBS patch in our text format.
#include <cstdio>
#include <filesystem>

#include "cad/fixtures.h"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s DIR\n", argv[0]);
    return 2;
  }
  std::error_code error;
  std::filesystem::create_directories(argv[1], error);
  auto written = sfc::cad::fixtures::WriteAll(argv[1]);
  if (!written.ok()) {
    std::fprintf(stderr, "make_cad_fixtures: %s\n", written.status().ToString().c_str());
    return 1;
  }
  for (const std::string& path : *written) std::printf("%s\n", path.c_str());
  return 0;
}
