// Loading a CAD model from bytes in memory: STEP, IGES, or our NURBS patch
// text format (docs/NURBS_FORMAT.md).
//
// The bytes come from the caller (a client's upload, a file the CLI read);
// Load never opens a path it is given. IGES, which OpenCASCADE reads only from
// files, goes through a private temporary file that Load creates (mode 0600)
// and deletes before returning.
//
// Thread-safety: Load may be called from many threads; the STEP and IGES
// readers keep global state in the kernel, so those reads are serialised by
// one process-wide mutex (NURBS patches too: they are quick).
#ifndef SFCSAMPLER_CAD_LOAD_H_
#define SFCSAMPLER_CAD_LOAD_H_

#include <cstddef>
#include <functional>
#include <memory>
#include <string>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "cad/model.h"
#include "cad/preflight.h"
#include "request/model_spec.h"

namespace sfc::cad {

// The CAD formats of request/model_spec.h's ModelFormat (the one enum of
// model formats): kStep, kIges and kNurbs.
bool IsCadFormat(ModelFormat format);

// A CAD format by its name or a file extension of it (request/model_files.h),
// in any case: "step" (also "stp"), "iges" (also "igs"), "nurbs";
// INVALID_ARGUMENT otherwise.
absl::StatusOr<ModelFormat> ParseModelFormat(absl::string_view text);

struct LoadOptions {
  // Largest model accepted, in bytes; a larger one is RESOURCE_EXHAUSTED.
  // Default 64 MiB.
  size_t max_bytes = size_t{64} << 20;
  // Tolerance of the trim classification, as a fraction of the parameter
  // box's larger side (points this close to a trim curve count as inside).
  // Default 1e-9.
  double trim_tolerance = 1e-9;
  // Planes, cylinders, cones, spheres and tori without a transformation are
  // evaluated from their closed forms (Face::closed_form(): SLEEF's sines and
  // cosines, so the same bits on every machine; within a few ulp of the
  // kernel's values, checked at load); false evaluates every face through
  // the kernel, to compare the two.
  bool closed_forms = true;
  // What the kernel's readers are spared (cad/preflight.h).
  PreflightLimits preflight;
  // Asked while the kernel works (OpenCASCADE's user break, polled by the
  // transfer and shape healing) and between faces; a non-OK status stops the
  // load, which returns it. Empty: never stop.
  std::function<absl::Status()> check;
};

// Reads a model from `bytes`. `name` names the input in every error message
// (e.g. the file name the user gave); it is escaped and clipped there
// (base/echo.h), as is every piece of the input a message quotes. Errors:
//   RESOURCE_EXHAUSTED  bytes.size() > options.max_bytes;
//   INVALID_ARGUMENT    a STEP/IGES past a PreflightLimits limit (nesting,
//                       entities, record or line length); face entities of
//                       the file that did not become faces, or errors the
//                       reader reported while loading it (nothing is dropped
//                       silently); unreadable or truncated STEP/IGES, a model without
//                       faces, an unbounded face, non-finite geometry, a
//                       malformed NURBS patch (knots, multiplicities,
//                       weights, counts, NaN); a mesh format (OBJ, PLY);
//   INTERNAL            the kernel failed in an unexpected way (its
//                       exception's message is passed on);
//   options.check's status, when it stopped the load.
// Never throws: the kernel's Standard_Failure is caught here, and so is a
// fault inside the kernel on malformed input (a null dereference in the IGES
// reader), which the kernel's signal handlers turn into a Standard_Failure;
// Load installs them for signals that have no handler yet
// (cad/internal/kernel_setup.h). Such a fault leaks that load's kernel objects.
absl::StatusOr<std::shared_ptr<const Model>> Load(ModelFormat format, absl::string_view bytes,
                                                  absl::string_view name,
                                                  const LoadOptions& options = {});

// Load in two halves, for reading a file in a process of its own
// (kinds/cad/model_check.h). ReadToBrep does all of Load's reading and
// checking and returns the model's shape as OpenCASCADE's binary BRep
// (BinTools); errors as Load's. LoadBrep makes the model of such bytes, as
// Load would have of the file: the same faces in the same order, the same
// geometry to the bit. `brep` must come from ReadToBrep (it is not checked
// as a hostile file would be); `format` and `name` are for messages.
absl::StatusOr<std::string> ReadToBrep(ModelFormat format, absl::string_view bytes,
                                       absl::string_view name, const LoadOptions& options = {});
absl::StatusOr<std::shared_ptr<const Model>> LoadBrep(absl::string_view brep, ModelFormat format,
                                                      absl::string_view name,
                                                      const LoadOptions& options = {});

}  // namespace sfc::cad

#endif  // SFCSAMPLER_CAD_LOAD_H_
