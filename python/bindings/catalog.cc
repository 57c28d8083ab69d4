// sfcsampler._core.surfaces() and densities(): the catalogue, as `sfcsampler
// surfaces` prints it. Pure functions of constant data; thread-safe.
#include "catalog/catalog.h"

#include "pybind11/pybind11.h"
#include "pybind11/stl.h"
#include "python/bindings/register.h"

namespace py = pybind11;

namespace sfc::python {
namespace {

py::list Entries(const std::vector<CatalogEntry>& entries) {
  py::list out;
  for (const CatalogEntry& e : entries) {
    py::list parameters;
    for (const CatalogParameter& p : e.parameters) {
      parameters.append(py::dict(py::arg("name") = p.name,
                                 py::arg("default_value") = p.default_value,
                                 py::arg("meaning") = p.meaning));
    }
    out.append(py::dict(py::arg("name") = e.name, py::arg("formula") = e.formula,
                        py::arg("description") = e.description,
                        py::arg("parameters") = parameters));
  }
  return out;
}

}  // namespace

void RegisterCatalog(py::module_& m) {
  m.def(
      "surfaces", [] { return Entries(SurfaceCatalog()); },
      "The built-in surfaces: a list of dicts with name, formula, description, parameters.");
  m.def(
      "densities", [] { return Entries(DensityCatalog()); },
      "The built-in densities, as surfaces() lists the surfaces.");
}

}  // namespace sfc::python
