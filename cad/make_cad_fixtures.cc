// make_cad_fixtures DIR: writes the project's CAD test models (cad/fixtures.h)
// into DIR: a sphere, a cylinder and a box with a fillet and a through hole as
// STEP and IGES, and a NURBS patch in our text format.
// make_cad_fixtures DIR --polygon N: writes only DIR/polygon_N.step, one face
// bounded by N corners (fixtures::PolygonFaceStep: a slow read for the
// kernel, for isolation benchmarks); --collinear N: DIR/collinear_N.step, N
// faces without area (fixtures::CollinearFacesStep).
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "cad/fixtures.h"

int main(int argc, char** argv) {
  const std::string kind = argc == 4 ? argv[2] : "";
  const int n = argc == 4 ? std::atoi(argv[3]) : 0;
  if (argc != 2 && !((kind == "--polygon" && n >= 3) || (kind == "--collinear" && n >= 1))) {
    std::fprintf(stderr, "usage: %s DIR [--polygon CORNERS | --collinear FACES]\n", argv[0]);
    return 2;
  }
  std::error_code error;
  std::filesystem::create_directories(argv[1], error);
  if (argc == 4) {
    const std::string path = std::string(argv[1]) + "/" + kind.substr(2) + "_" + argv[3] + ".step";
    std::ofstream(path, std::ios::binary)
        << (kind == "--polygon" ? sfc::cad::fixtures::PolygonFaceStep(n)
                                : sfc::cad::fixtures::CollinearFacesStep(n, false));
    std::printf("%s\n", path.c_str());
    return 0;
  }
  auto written = sfc::cad::fixtures::WriteAll(argv[1]);
  if (!written.ok()) {
    std::fprintf(stderr, "make_cad_fixtures: %s\n", written.status().ToString().c_str());
    return 1;
  }
  for (const std::string& path : *written) std::printf("%s\n", path.c_str());
  return 0;
}
