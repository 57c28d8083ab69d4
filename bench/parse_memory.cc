// Measures what parsing a model costs in memory at its peak, against the
// file's size and against what the parsed model keeps: the figures behind
// the parse reservations of kinds/cad and kinds/mesh (docs/MODELS.md).
// Each model is parsed by a fresh process (this program run again with
// --one), so no memory freed before, by this program or a parse before, hides
// the parse's peak; the peak is the growth of that process's VmHWM over its
// VmRSS just before the parse. The kernel's one-time set-up (OpenCASCADE's
// ~16 MB on its first STEP or IGES) is paid there too: small files show it,
// large ones their ratio.
//   parse_memory DIR [LARGE_SUBDIVISIONS] [CAD_COPIES]
//       writes the soak's models into DIR, and STEP and IGES files of
//       CAD_COPIES (default 400) boxes with a hole, then measures them all
//   parse_memory FORMAT:FILE...
//   parse_memory --worst DIR [MB]  (the meshes that cost the most a byte:
//       mesh/mesh_loader.h's MeshParseMemoryBytes; MB, default 16, each)
//   parse_memory --repeat N FORMAT:FILE    (N parses in one process: VmRSS)
//   parse_memory --time-reads FORMAT:FILE  (Load against ReadToBrep + LoadBrep)
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/numbers.h"
#include "absl/strings/str_format.h"
#include "bench/soak_models.h"
#include "cad/fixtures.h"
#include "cad/load.h"
#include "mesh/mesh_loader.h"
#include "mesh/mesh_surface.h"
#include "request/model_spec.h"

namespace {

// A field of /proc/self/status in bytes ("VmRSS", "VmHWM").
uint64_t StatusBytes(const std::string& field) {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind(field + ":", 0) == 0) return std::stoull(line.substr(field.size() + 1)) * 1024;
  }
  return 0;
}

// The model FORMAT:FILE names, read as the CLI reads it (request/model_spec.h);
// prints why not and returns nullopt when it cannot be read.
std::optional<sfc::StoredModel> ReadSpec(const std::string& spec) {
  auto parsed = sfc::ParseModelSpec(spec);
  absl::StatusOr<sfc::StoredModel> model =
      !parsed.ok()             ? parsed.status()
      : !parsed->has_value()   ? absl::InvalidArgumentError("not FORMAT:FILE")
                               : sfc::ReadModelFile(**parsed, uint64_t{1} << 32);
  if (!model.ok()) {
    std::fprintf(stderr, "%s: %s\n", spec.c_str(), model.status().ToString().c_str());
    return std::nullopt;
  }
  return *std::move(model);
}

// Parses `spec` (FORMAT:FILE) and prints one row. Runs in a child.
int Measure(const std::string& spec, bool curvature) {
  const std::optional<sfc::StoredModel> model = ReadSpec(spec);
  if (!model) return 1;
  const std::string format(sfc::ModelFormatName(model->format)), &path = model->name;
  const std::string& bytes = *model->bytes;
  // Reset the peak to now (Linux: clear_refs 5), then parse.
  std::ofstream("/proc/self/clear_refs") << "5";
  const uint64_t before = StatusBytes("VmRSS");
  std::string what = "ok";
  if (format == "ply" || format == "obj") {
    sfc::MeshLoadOptions options;
    options.format = model->format;
    auto mesh = sfc::LoadMesh(bytes, path, options);
    if (!mesh.ok()) {
      what = std::string(mesh.status().message()).substr(0, 60);
    } else {
      auto surface = sfc::MeshSurface::Create(*std::move(mesh), curvature);
    }
  } else {
    auto parsed = sfc::cad::Load(model->format, bytes, path, {});
    if (!parsed.ok()) what = std::string(parsed.status().message()).substr(0, 60);
  }
  const uint64_t peak = StatusBytes("VmHWM");
  const double growth = peak > before ? static_cast<double>(peak - before) : 0.0;
  if (format == "ply" || format == "obj") {
    what += absl::StrFormat(" (reserved %.1f a byte)",
                            static_cast<double>(sfc::MeshParseMemoryBytes(model->format, bytes)) /
                                static_cast<double>(bytes.size()));
  }
  std::printf("%-6s %-10s %12zu %12.0f %8.2f  %s\n", format.c_str(), curvature ? "curvature" : "",
              bytes.size(), growth, growth / static_cast<double>(bytes.size()), what.c_str());
  std::fflush(stdout);
  return 0;
}

// STEP and IGES files of `copies` boxes with a hole side by side, in `dir`.
bool WriteCadArrays(const std::string& dir, int copies, std::vector<std::string>* specs) {
  namespace fixtures = sfc::cad::fixtures;
  for (auto [format, name] :
       {std::pair{sfc::ModelFormat::kStep, "step"}, std::pair{sfc::ModelFormat::kIges, "iges"}}) {
    auto bytes = fixtures::SolidBytes(fixtures::Solid::kBoxWithHole, format, copies);
    if (!bytes.ok()) return false;
    const std::string path = dir + "/boxes." + name;
    std::ofstream(path, std::ios::binary) << *bytes;
    specs->push_back(std::string(name) + ":" + path);
  }
  return true;
}

// The meshes that cost the most memory a byte of file, of about `size`
// bytes each, in `dir`: OBJ lines "f 1 2 3" (tinyobjloader's faces), OBJ and
// ASCII PLY faces of 100 one-digit corners (a triangle every two bytes),
// binary PLY faces of 255 uchar corners (a triangle every byte).
bool WriteWorstMeshes(const std::string& dir, size_t size, std::vector<std::string>* specs) {
  auto write = [&](const std::string& name, const std::string& head, const std::string& unit) {
    std::ofstream out(dir + "/" + name, std::ios::binary);
    out << head;
    for (size_t n = head.size(); n < size; n += unit.size()) out << unit;
    specs->push_back(name.substr(name.rfind('.') + 1) + ":" + dir + "/" + name);
    return static_cast<bool>(out);
  };
  std::string obj_polygon = "f", ascii_face = "100", binary_face(1, '\xff');
  for (int c = 0; c < 100; ++c) obj_polygon += absl::StrFormat(" %d", c % 3 + 1);
  for (int c = 0; c < 100; ++c) ascii_face += absl::StrFormat(" %d", c % 3);
  for (int c = 0; c < 255; ++c) binary_face += static_cast<char>(c % 3);
  const std::string vertices = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  auto ply_head = [&](const char* encoding, const std::string& face, const char* index) {
    const float corners[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    const bool binary = std::string(encoding) != "ascii";
    return absl::StrFormat(
               "ply\nformat %s 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
               "property float z\nelement face %d\nproperty list uchar %s "
               "vertex_indices\nend_header\n",
               encoding, size / face.size(), index) +
           (binary ? std::string(reinterpret_cast<const char*>(corners), sizeof(corners))
                   : "0 0 0\n1 0 0\n0 1 0\n");
  };
  // A PLY's face count is exact: its faces fill `size` less nothing.
  auto write_ply = [&](const std::string& name, const char* encoding, const std::string& face,
                       const char* index) {
    std::ofstream out(dir + "/" + name, std::ios::binary);
    out << ply_head(encoding, face, index);
    for (size_t f = 0; f < size / face.size(); ++f) out << face;
    specs->push_back("ply:" + dir + "/" + name);
    return static_cast<bool>(out);
  };
  return write("worst_triangles.obj", vertices, "f 1 2 3\n") &&
         write("worst_polygons.obj", vertices, obj_polygon + "\n") &&
         write_ply("worst_ascii.ply", "ascii", ascii_face + "\n", "int") &&
         write_ply("worst_binary.ply", "binary_little_endian", binary_face, "uchar");
}

// Parses `spec` `times` times in this process and prints VmRSS every tenth
// of the way: memory a parse leaves behind shows as growth.
int Repeat(const std::string& spec, int times) {
  const std::optional<sfc::StoredModel> model = ReadSpec(spec);
  if (!model) return 1;
  const std::string format(sfc::ModelFormatName(model->format)), &path = model->name;
  const std::string& bytes = *model->bytes;
  auto f = sfc::cad::ParseModelFormat(format);
  if (!f.ok()) return 2;
  for (int i = 1; i <= times; ++i) {
    auto loaded = sfc::cad::Load(*f, bytes, path, {});
    if (i % std::max(1, times / 10) == 0) {
      std::printf("%s: after %d parses (%s) VmRSS %.1f MiB\n", spec.c_str(), i,
                  loaded.ok() ? "ok" : "refused", StatusBytes("VmRSS") / 1048576.0);
      std::fflush(stdout);
    }
  }
  return 0;
}

// Times the two ways a model is read: cad::Load in this process, and
// cad::ReadToBrep (what the model check process does) then cad::LoadBrep
// (what the server does with its answer).
int TimeReads(const std::string& spec) {
  const std::optional<sfc::StoredModel> model = ReadSpec(spec);
  if (!model) return 1;
  const std::string format(sfc::ModelFormatName(model->format)), &path = model->name;
  const std::string& bytes = *model->bytes;
  auto f = sfc::cad::ParseModelFormat(format);
  if (!f.ok()) return 2;
  sfc::cad::LoadOptions options;
  options.max_bytes = bytes.size();
  auto seconds = [](auto&& work) {
    const auto start = std::chrono::steady_clock::now();
    work();
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  absl::StatusOr<std::string> brep;
  const double load = seconds([&] { (void)sfc::cad::Load(*f, bytes, path, options); });
  const double read = seconds([&] { brep = sfc::cad::ReadToBrep(*f, bytes, path, options); });
  if (!brep.ok()) {
    std::fprintf(stderr, "%s: %s\n", spec.c_str(), brep.status().ToString().c_str());
    return 1;
  }
  const double load_brep = seconds([&] { (void)sfc::cad::LoadBrep(*brep, *f, path, options); });
  std::printf(
      "%s: %zu bytes; Load %.3f s; ReadToBrep %.3f s (%zu bytes of BRep); LoadBrep %.3f s\n",
      spec.c_str(), bytes.size(), load, read, brep->size(), load_brep);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc == 4 && std::string(argv[1]) == "--one")
    return Measure(argv[2], std::string(argv[3]) == "1");
  if (argc == 3 && std::string(argv[1]) == "--time-reads") return TimeReads(argv[2]);
  if (argc == 4 && std::string(argv[1]) == "--repeat") return Repeat(argv[3], std::atoi(argv[2]));
  if (argc < 2) {
    std::fprintf(stderr, "usage: parse_memory DIR [LARGE_SUBDIVISIONS] | FORMAT:FILE...\n");
    return 2;
  }
  std::vector<std::string> specs;
  if (std::string(argv[1]) == "--worst") {
    int mb = 16;
    if (argc < 3 || (argc > 3 && !absl::SimpleAtoi(argv[3], &mb))) return 2;
    if (!WriteWorstMeshes(argv[2], size_t(mb) << 20, &specs)) {
      std::fprintf(stderr, "could not write the meshes into %s\n", argv[2]);
      return 1;
    }
  } else if (std::string(argv[1]).find(':') == std::string::npos) {
    int subdivisions = 8;
    if (argc > 2 && !absl::SimpleAtoi(argv[2], &subdivisions)) return 2;
    auto models = sfc::SoakModels::Write(argv[1], subdivisions);
    if (!models.ok()) {
      std::fprintf(stderr, "%s\n", models.status().ToString().c_str());
      return 1;
    }
    for (const auto& m : models->good()) specs.push_back(m.spec);
    for (const auto& m : models->large()) specs.push_back(m.spec);
    int copies = 400;
    if (argc > 3 && !absl::SimpleAtoi(argv[3], &copies)) return 2;
    if (!WriteCadArrays(argv[1], copies, &specs)) {
      std::fprintf(stderr, "could not write the STEP and IGES arrays\n");
      return 1;
    }
  } else {
    for (int i = 1; i < argc; ++i) specs.push_back(argv[i]);
  }
  std::printf("%-6s %-10s %12s %12s %8s  %s\n", "format", "", "file bytes", "peak growth", "ratio",
              "result");
  for (const std::string& spec : specs) {
    for (bool curvature : {false, true}) {
      const bool mesh = spec.rfind("ply:", 0) == 0 || spec.rfind("obj:", 0) == 0;
      if (curvature && !mesh) continue;
      std::fflush(stdout);
      const pid_t child = fork();
      if (child == 0) {
        execl("/proc/self/exe", argv[0], "--one", spec.c_str(), curvature ? "1" : "0", nullptr);
        _exit(127);
      }
      int status = 0;
      waitpid(child, &status, 0);
    }
  }
  return 0;
}
