// Issue 19's quality report: measures that an independent reviewer would
// use, each with its seeds, standard error and a PASS/FAIL against the
// issue's "What must hold":
//  - density discrepancy of the superellipsoid family on sample-anchored
//    boxes against a graded reference (evaluation/box_discrepancy.h), slopes
//    as the mean of >= 3 seeds with their standard error; the old 256-grid
//    measure on the same sets next to it;
//  - strip counts beside every singular line at N = 200 000 against the
//    closed-form fractions (evaluation/superellipsoid_exact.h);
//  - the spread across seeds of the counts in thin bands beside the lines
//    (stratification), against the reparameterised surface's;
//  - the Monte Carlo mean of x^2 against its exact value;
//  - plane (star discrepancy, ours against 2D jittered), sphere (spherical
//    triangles), a sphere-shaped CAD model and mesh against the built-in;
//  - blue-noise figures (nearest-neighbour distances relative to hexagonal
//    packing) at N = 4096 on the plane and the sphere;
//  - issue 33's generic features: density steps on the plane, a cube-root
//    blow-up line and the double cone's kink at irrational positions (off the
//    grid of every curve), strip counts and means against closed forms, and
//    an N sweep of a step's share error with its slope;
//  - issue 36's integration table (evaluation/integration.h).
// Nothing here reads the curve tree: point sets come from `QualitySource`.
//
// Thread-safety: RunQuality is reentrant.
#ifndef SFCSAMPLER_EVALUATION_QUALITY_H_
#define SFCSAMPLER_EVALUATION_QUALITY_H_

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/types/sample_batch.h"
#include "core/types/sequence_kind.h"

namespace sfc {

// Our set of `count` samples with `seed` of `sequence` (jittered unless a
// section says otherwise) on catalogue specs (model specs such as step:FILE
// or ply:FILE included), all of it, with u, v, x, y, z.
using QualitySource = std::function<absl::StatusOr<SampleBatch>(
    const std::string& surface, const std::string& density, uint64_t count, uint64_t seed,
    SequenceKind sequence)>;

struct QualityOptions {
  // full: the sizes (boxes N = 64..24576, strips at 200 000, Monte
  // Carlo to 10^6; features: steps at 10^6 and 4 10^6, blow-up 2^18, cone
  // 2^20, sweep 2^16..2^22; minutes). Otherwise a fast setting for tests
  // (seconds; features at 2^18, sweep 2^14..2^18).
  bool full = false;
  std::vector<uint64_t> seeds = {1, 2, 3};             // slopes and Monte Carlo
  std::vector<uint64_t> strip_seeds = {5, 6, 7};       // strips (the seed 5 first)
  std::vector<std::string> sections;  // empty: all of boxes strips bands mc plane sphere models
                                      // blue features (integration only when named)
  std::string step_sphere;  // model spec of a sphere (step:/tmp/fx/sphere.step); empty: skipped
  std::string mesh_sphere;  // model spec of a sphere mesh (ply:/tmp/ico.ply); empty: skipped
  std::string out_dir = ".";  // where a section writes its files (integration's icosphere OBJ)
  std::function<void(const std::string&)> progress;  // one line per finished item
};

struct QualityCheck {
  std::string name;      // what is checked
  std::string measured;  // mean +- standard error, or the worst case
  std::string target;    // the target; empty: a measurement only
  std::string verdict;   // PASS, FAIL or INFO
};

struct QualityReport {
  std::vector<QualityCheck> checks;
  std::string tables;  // markdown: every figure with its seeds
  // Pictures (file name, SVG text) the tables refer to, for the output folder.
  std::vector<std::pair<std::string, std::string>> pictures;
};

absl::StatusOr<QualityReport> RunQuality(const QualityOptions& options,
                                         const QualitySource& source);

// The summary table of `checks` (markdown).
std::string QualitySummary(const std::vector<QualityCheck>& checks);

// Mean and standard error of the mean (0 for fewer than 2 values).
void MeanAndStandardError(const std::vector<double>& x, double* mean, double* se);

}  // namespace sfc

#endif  // SFCSAMPLER_EVALUATION_QUALITY_H_
