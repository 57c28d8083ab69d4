// describe_model FILE [FORMAT]: loads a STEP, IGES or NURBS file (the format
// from FORMAT or the file's extension) and prints DescribeModel: each face's
// index, type, trimmed area and parameter box, and the curve order. The core
// of the CLI's future `sfcsampler inspect`.
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "cad/load.h"
#include "cad/model.h"

int main(int argc, char** argv) {
  if (argc != 2 && argc != 3) {
    std::fprintf(stderr, "usage: %s FILE [step|iges|nurbs]\n", argv[0]);
    return 2;
  }
  const std::string path = argv[1];
  std::string format_text = argc == 3 ? argv[2] : std::filesystem::path(path).extension().string();
  if (!format_text.empty() && format_text[0] == '.') format_text.erase(0, 1);
  auto format = sfc::cad::ParseModelFormat(format_text);
  if (!format.ok()) {
    std::fprintf(stderr, "describe_model: %s\n", format.status().ToString().c_str());
    return 2;
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    std::fprintf(stderr, "describe_model: cannot read %s\n", path.c_str());
    return 1;
  }
  std::ostringstream bytes;
  bytes << in.rdbuf();
  auto model = sfc::cad::Load(*format, bytes.str(), path);
  if (!model.ok()) {
    std::fprintf(stderr, "describe_model: %s\n", model.status().ToString().c_str());
    return 1;
  }
  std::fputs(sfc::cad::DescribeModel(**model).c_str(), stdout);
  return 0;
}
