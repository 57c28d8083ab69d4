// `sfcsampler sample-many`: samples many model files (STEP, IGES, NURBS, OBJ,
// PLY) in one run, one output file per model, several models at a time.
//
// Inputs are folders (their model files by extension, subfolders too), glob
// patterns (glob(3): no "**"), list files (one path a line, relative to the
// list's folder; blank lines and # comments skipped) or model files. A model's
// name is its path relative to the folder, the pattern's folder or the list's
// folder, and its output is OUT_DIR/NAME with the model extension replaced by
// the format's (kept when two models share a stem, as part.step and part.iges),
// so a dataset's tree (ShapeNet's <synset>/<id>/models/model_normalized.obj) is
// mirrored. Each model's seed comes from
// the base --seed and the model's content hash (ModelSeed in
// request/model_spec.h), so a model's
// output does not depend on the order of the inputs or on --jobs, and equals
// `sfcsampler sample --surface FORMAT:FILE --seed <its seed>` on it alone
// (--face applies to the CAD models and --triangle to the meshes). A
// model that fails is reported by name with its error, the others go on; the
// summary comes at the end and the exit status is 1 if any failed (2 for
// bad flags or inputs that name no models). With --server every model goes
// to the server (uploaded only if it lacks the bytes) and the outputs are the
// same bytes.
//
// Thread-safety: RunSampleMany runs its own worker threads.
#ifndef SFCSAMPLER_CLIENT_CLI_SAMPLE_MANY_H_
#define SFCSAMPLER_CLIENT_CLI_SAMPLE_MANY_H_

#include <cstdint>
#include <string>
#include <vector>

#include "CLI/CLI.hpp"
#include "client/cli/connection_flags.h"
#include "client/cli/model_read_flags.h"
#include "request/request_flags.h"

namespace sfc {

struct SampleManyFlags {
  std::vector<std::string> inputs;
  std::string out_dir = "samples";
  std::string format = "npy";  // npy | csv | ply
  bool ascii = false;
  std::string precision = "float64";
  std::vector<std::string> columns;  // --columns: the columns to write (empty: all)
  int jobs = 0;                 // 0: the hardware threads, at most 8
  std::string manifest;         // a TSV of every model's outcome, or ""
  bool quiet = false;
  // In process, CAD files are read each in a process of its own (so a file
  // that crashes or loops the kernel, or leaves it broken for the next,
  // fails alone).
  ModelReadFlags model_read;
  ConnectionFlags connection;   // --server etc.; no --server = in process
  RequestFlags request;         // every model's request but the surface and seed
};

// Runs it; returns the exit status. AddSampleManyCommand (commands.h) adds
// the subcommand and its flags.
int RunSampleMany(const SampleManyFlags& flags);

}  // namespace sfc

#endif  // SFCSAMPLER_CLIENT_CLI_SAMPLE_MANY_H_
