#include "request/request_flags.h"

#include <cmath>
#include <vector>

#include "absl/strings/numbers.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_split.h"
#include "base/echo.h"
#include "base/status_macros.h"

namespace sfc {
namespace {

absl::StatusOr<std::vector<double>> Numbers(const std::string& what, absl::string_view text,
                                            size_t expected) {
  std::vector<double> values;
  for (absl::string_view part : absl::StrSplit(text, ',')) {
    double v;
    if (!absl::SimpleAtod(part, &v)) {
      return absl::InvalidArgumentError(
          absl::StrFormat("%s: \"%s\" is not a number", what, std::string(part)));
    }
    values.push_back(v);
  }
  if (values.size() != expected) {
    return absl::InvalidArgumentError(absl::StrFormat("%s takes %d comma-separated numbers, got %d",
                                                      what, expected, values.size()));
  }
  return values;
}

}  // namespace

// CLI11 reads "-1" and numbers past 2^64 - 1 into a uint64_t as 2^64 - 1
// without a word, so runs a user believes independent would share a seed:
// whole-number flags are checked as typed, before that conversion.
const CLI::Validator kWholeNumber(
    [](std::string& text) -> std::string {
      uint64_t value;
      if (!text.empty() && text.find_first_not_of("0123456789") == std::string::npos &&
          absl::SimpleAtoi(text, &value)) {
        return "";
      }
      return absl::StrFormat("must be a whole number from 0 to 18446744073709551615 "
                             "(2^64 - 1), got '%s'",
                             Echo(text));
    },
    "UINT64");

void AddTreeFlags(CLI::App* cmd, RequestFlags* f) {
  cmd->add_option("--surface", f->surface,
                  "surface spec, e.g. sphere, torus:R=2;r=0.5 (see `surfaces`)")
      ->capture_default_str();
  cmd->add_option("--density", f->density, "density spec: uniform, gaussian, mean, expr:EXPRESSION")
      ->capture_default_str();
  cmd->add_option("--curve", f->curve, "hilbert | hilbert2 | peano")->capture_default_str();
  cmd->add_option("--estimator", f->estimator,
                  "area x density estimator: triangle | square | fff | quadrature")
      ->capture_default_str();
  cmd->add_option("--tolerance", f->tolerance,
                  "the paper's a, surface units (0 = 1% of the bounding-box diagonal)")
      ->capture_default_str();
  cmd->add_option("--depth-cap", f->depth_cap, "the paper's r (0 = the curve's deepest level)")
      ->capture_default_str();
  cmd->add_option("--rho", f->rho, "max samples' worth of mass per leaf")->capture_default_str();
}

void AddSampleFlags(CLI::App* cmd, RequestFlags* f) {
  cmd->add_option("--count,-n", f->count, "N, the number of samples in the set")
      ->capture_default_str()
      ->check(kWholeNumber);
  cmd->add_option("--seed", f->seed, "random seed")->capture_default_str()->check(kWholeNumber);
  cmd->add_option("--sequence", f->sequence,
                  "jittered | equal | random | vandercorput | progressive | blue (evenly "
                  "spaced; biased for integration) | sobol (integration)")
      ->capture_default_str();
  cmd->add_option(
         "--tree-count", f->tree_count,
         "size the tree for this many samples (default: --count); keep it fixed to extend a "
         "progressive set byte-exactly")
      ->check(kWholeNumber);
  cmd->add_option("--begin", f->begin, "first index of the range to return")->check(kWholeNumber);
  cmd->add_option("--end", f->end, "one past the last index (default: count)")->check(kWholeNumber);
  cmd->add_option("--shard", f->shard, "shard i/K of the set (a contiguous stretch of the curve)");
  cmd->add_option("--region", f->region,
                  "only samples inside uv:U0,U1,V0,V1 (parameter rectangle) or "
                  "box:X0,Y0,Z0,X1,Y1,Z1 (3D box)");
  cmd->add_flag("--normals", f->normals, "add unit normals nx,ny,nz");
  cmd->add_flag("--density-column", f->density_column, "add the density value at each sample");
  cmd->add_flag("--curve-position", f->curve_position, "add the position along the curve in [0,1)");
  cmd->add_flag("--face", f->face, "CAD models: add each sample's face index (file order)");
  cmd->add_flag("--triangle", f->triangle,
                "meshes: add each sample's triangle index (file order); u,v are then barycentric");
}

absl::StatusOr<TreeSpec> ToTreeSpec(const RequestFlags& f) {
  TreeSpec spec;
  spec.surface = f.surface;
  spec.density = f.density;
  const auto curve = CurveFromName(f.curve);
  if (!curve) return absl::InvalidArgumentError("--curve must be hilbert, hilbert2 or peano");
  const auto estimator = AreaEstimatorFromName(f.estimator);
  if (!estimator) {
    return absl::InvalidArgumentError("--estimator must be triangle, square, fff or quadrature");
  }
  spec.options.curve = *curve;
  spec.options.estimator = *estimator;
  spec.options.tolerance = f.tolerance;
  spec.options.depth_cap = f.depth_cap;
  spec.options.rho = f.rho;
  // Checked here, before a request is sent: a server cannot tell a 0 from an
  // old client's unset field (proto/sfcsampler/v1/sampler.proto).
  if (!(f.rho > 0) || !std::isfinite(f.rho)) {
    return absl::InvalidArgumentError(
        absl::StrFormat("--rho must be a positive number (samples' worth of mass a leaf may hold; "
                        "default 1), got %g",
                        f.rho));
  }
  return spec;
}

absl::StatusOr<SampleRequest> ToSampleRequest(const RequestFlags& f) {
  SampleRequest r;
  ASSIGN_OR_RETURN(r.tree, ToTreeSpec(f));
  const auto sequence = SequenceFromName(f.sequence);
  if (!sequence) {
    return absl::InvalidArgumentError(
        "--sequence must be jittered, equal, random, vandercorput, progressive, blue or sobol");
  }
  r.sequence = *sequence;
  r.count = f.count;
  r.seed = f.seed;
  r.tree_count = f.tree_count;
  r.begin = f.begin;
  r.end = f.end;
  if (!f.shard.empty()) {
    const std::vector<std::string> parts = absl::StrSplit(f.shard, '/');
    if (parts.size() != 2 || !absl::SimpleAtoi(parts[0], &r.shard_index) ||
        !absl::SimpleAtoi(parts[1], &r.shard_count) || r.shard_count == 0) {
      return absl::InvalidArgumentError("--shard takes i/K with 0 <= i < K, e.g. 2/8");
    }
  }
  if (!f.region.empty()) {
    if (f.region.rfind("uv:", 0) == 0) {
      ASSIGN_OR_RETURN(const auto v, Numbers("--region uv:", f.region.substr(3), 4));
      r.region = Region::ParameterRect(v[0], v[1], v[2], v[3]);
    } else if (f.region.rfind("box:", 0) == 0) {
      ASSIGN_OR_RETURN(const auto v, Numbers("--region box:", f.region.substr(4), 6));
      r.region = Region::Box({v[0], v[1], v[2]}, {v[3], v[4], v[5]});
    } else {
      return absl::InvalidArgumentError(
          "--region takes uv:U0,U1,V0,V1 or box:X0,Y0,Z0,X1,Y1,Z1");
    }
  }
  r.fields.normal = f.normals;
  r.fields.density = f.density_column;
  r.fields.curve_position = f.curve_position;
  r.fields.face = f.face;
  r.fields.triangle = f.triangle;
  return r;
}

}  // namespace sfc
