// The evaluation protocol of paper Sects. 4-5 (docs/ALGORITHM.md): discrepancy of
// point sets of N = 2^l and 2^l + 2^(l-1) points for our sampler and the
// reference sets, on the unit square (anchored boxes, quarter discs,
// triangles) and the unit sphere (spherical triangles), with least-squares
// slopes of log D against log N next to the paper's Tables 1 and 2.
//
// Thread-safety: RunProtocol is reentrant; nothing is shared.
#ifndef SFCSAMPLER_EVALUATION_PROTOCOL_H_
#define SFCSAMPLER_EVALUATION_PROTOCOL_H_

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/curve_tree.h"
#include "core/types/sample_batch.h"

namespace sfc {

// Where our sampler's point sets come from when they are not made in-process:
// the jittered set of `count` samples (seed `seed`) on the catalogue specs
// `surface` and `density` with tree `options`, all of it, in curve order
// (e.g. from a server, `sfcsampler eval --server`).
using PointSetSource = std::function<absl::StatusOr<SampleBatch>(
    const std::string& surface, const std::string& density, const CurveTreeOptions& options,
    uint64_t count, uint64_t seed)>;

struct ProtocolOptions {
  int l_min = 1;
  int l_max = 13;  // the fast setting (N up to 12288); the paper goes to 20 (1572864 points)
  std::vector<std::string> plane_methods;   // empty: all
  std::vector<std::string> sphere_methods;  // empty: all
  bool surfaces = true;  // also the density discrepancy on other surfaces
  uint64_t seed = 1;
  int star_corners = 2048;    // see StarDiscrepancy
  int triangle_grid = 256;    // see TriangleDiscrepancy
  int sphere_triangles = 128; // see SphericalTriangleDiscrepancy
  PointSetSource our_sets;    // empty: our sets are made in-process
};

// One point set's discrepancies; absent measures do not apply to its domain.
struct ProtocolRow {
  std::string domain;  // "plane", "sphere", or "surface <spec> with <density>"
  std::string method;
  uint64_t n = 0;
  std::optional<double> rectangular, circular, triangular, spherical;
  std::optional<double> density;  // ParameterRectDiscrepancy, for "surface ..." domains
  double seconds = 0;  // time to make the set
};

struct SlopeRow {
  std::string domain, method, measure;
  double slope = 0;
  std::optional<double> paper;  // the paper's slope, where it reports one
};

const std::vector<std::string>& PlaneMethods();
const std::vector<std::string>& SphereMethods();

// `progress(done, total)` is called after each point set.
absl::StatusOr<std::vector<ProtocolRow>> RunProtocol(
    const ProtocolOptions& options, const std::function<void(int, int)>& progress = nullptr);

// Least-squares slope of log D against log N per method and measure.
std::vector<SlopeRow> Slopes(const std::vector<ProtocolRow>& rows);

std::string RowsCsv(const std::vector<ProtocolRow>& rows);
// Markdown tables: our slopes next to the paper's.
std::string SlopeTables(const std::vector<SlopeRow>& slopes);

}  // namespace sfc

#endif  // SFCSAMPLER_EVALUATION_PROTOCOL_H_
