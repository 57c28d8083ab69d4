// Helpers shared by the mesh tests: a scratch directory and file I/O.
#ifndef SFCSAMPLER_TESTS_MESH_TEST_UTIL_H_
#define SFCSAMPLER_TESTS_MESH_TEST_UTIL_H_

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace sfc::testing {

// A fresh directory under the test's temporary directory.
inline std::filesystem::path ScratchDir(const std::string& name) {
  const char* tmp = std::getenv("TEST_TMPDIR");
  std::filesystem::path dir = std::filesystem::path(tmp ? tmp : "/tmp") /
                              ("sfc_mesh_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  return dir;
}

inline void WriteFile(const std::filesystem::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

inline std::string ReadFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream out;
  out << in.rdbuf();
  return out.str();
}

}  // namespace sfc::testing

#endif  // SFCSAMPLER_TESTS_MESH_TEST_UTIL_H_
