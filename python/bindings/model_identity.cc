// sfcsampler._core.canonical_ply() and model_seed(): what names a model in a
// many-model run, its canonical bytes (python/bindings/mesh_arrays.h) and the
// seed its content hash gives (request/model_spec.h ModelSeed), the C++ the
// CLI and sample_many use, bound for meshes.canonical_ply() and
// many.model_seed(). Pure functions; thread-safe.
#include <cctype>
#include <cstdint>
#include <optional>
#include <string>

#include "pybind11/numpy.h"
#include "pybind11/pybind11.h"
#include "pybind11/stl.h"
#include "python/bindings/mesh_arrays.h"
#include "python/bindings/register.h"
#include "request/model_spec.h"

namespace py = pybind11;

namespace sfc::python {
namespace {

using Doubles = py::array_t<double, py::array::c_style | py::array::forcecast>;
using Indices = py::array_t<int32_t, py::array::c_style | py::array::forcecast>;

void RequireShape(const py::array& a, const char* what, py::ssize_t rows, py::ssize_t columns) {
  const bool ok = columns == 0
                      ? a.ndim() == 1 && a.shape(0) == rows
                      : a.ndim() == 2 && a.shape(1) == columns && (rows < 0 || a.shape(0) == rows);
  if (!ok) throw py::value_error(std::string(what) + " has the wrong shape");
}

py::bytes CanonicalPlyOf(const Doubles& vertices, const Indices& faces,
                         const std::optional<Doubles>& normals,
                         const std::optional<Doubles>& weights) {
  RequireShape(vertices, "vertices", -1, 3);
  RequireShape(faces, "faces", -1, 3);
  const py::ssize_t n = vertices.shape(0);
  if (normals) RequireShape(*normals, "normals", n, 3);
  if (weights) RequireShape(*weights, "weights", n, 0);
  std::string ply;
  bool ok;
  {
    py::gil_scoped_release release;  // the arrays stay alive (the caller holds them)
    ok = CanonicalPly(vertices.data(), static_cast<size_t>(n), normals ? normals->data() : nullptr,
                      weights ? weights->data() : nullptr, faces.data(), /*wide_faces=*/false,
                      static_cast<size_t>(faces.shape(0)), &ply);
  }
  if (!ok) throw py::value_error("the mesh fails a check of meshes.canonical_ply()");
  return py::bytes(ply);
}

uint64_t ModelSeedOf(const py::int_& base_seed, const std::string& sha256_hex) {
  // Python's int.to_bytes(8, "little") and bytes.fromhex() refuse the same.
  const uint64_t base = PyLong_AsUnsignedLongLong(base_seed.ptr());
  if (PyErr_Occurred()) throw py::error_already_set();
  bool hex = sha256_hex.size() % 2 == 0;
  for (char c : sha256_hex) hex &= std::isxdigit(static_cast<unsigned char>(c)) != 0;
  if (!hex) throw py::value_error("sha256_hex must be hex digits in pairs: " + sha256_hex);
  return ModelSeed(base, sha256_hex);
}

}  // namespace

void RegisterModelIdentity(py::module_& m) {
  m.attr("MESH_WEIGHT_PROPERTY") = kWeightProperty;
  m.def("canonical_ply", &CanonicalPlyOf, py::arg("vertices"), py::arg("faces"),
        py::arg("normals") = py::none(), py::arg("weights") = py::none(),
        "The canonical binary PLY bytes of checked arrays (meshes.canonical_ply() checks "
        "them first): vertices and normals float64 (n, 3), faces int32 (m, 3), weights "
        "float64 (n,).");
  m.def("model_seed", &ModelSeedOf, py::arg("base_seed"), py::arg("sha256_hex"),
        "The seed of a model in a many-model run: the first 8 bytes, big-endian, of "
        "SHA-256(\"sfcsampler.model-seed\\0\" + base_seed as 8 bytes little-endian + the "
        "hash's bytes), top bit cleared (request/model_spec.h ModelSeed, as the CLI).");
}

}  // namespace sfc::python
