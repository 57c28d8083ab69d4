// The parts of sfcsampler._core, one binding file each; module.cc calls them.
#ifndef SFCSAMPLER_PYTHON_BINDINGS_REGISTER_H_
#define SFCSAMPLER_PYTHON_BINDINGS_REGISTER_H_

#include "pybind11/pybind11.h"

namespace sfc::python {

void RegisterErrors(pybind11::module_& m);    // errors.cc: Status -> sfcsampler.errors
void RegisterRequest(pybind11::module_& m);   // request.cc: Request
void RegisterSampling(pybind11::module_& m);  // sampling.cc: Engine, Job
void RegisterCatalog(pybind11::module_& m);   // catalog.cc: surfaces(), densities()
// model_identity.cc: canonical_ply(), model_seed()
void RegisterModelIdentity(pybind11::module_& m);

}  // namespace sfc::python

#endif  // SFCSAMPLER_PYTHON_BINDINGS_REGISTER_H_
