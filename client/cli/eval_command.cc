// `sfcsampler eval`: issue 19's quality report (eval_quality.h) and the
// paper's discrepancy protocol (Tables 1-2, eval_protocol.h), or with
// --model a sphere-shaped model's spherical-triangle discrepancy against the
// built-in sphere (here). Our point sets come from the SampleSource (in
// process, or --server); the reference sets and the discrepancies are
// computed here.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "base/status_macros.h"
#include "client/cli/commands.h"
#include "client/cli/connection_flags.h"
#include "client/cli/eval_protocol.h"
#include "client/cli/eval_quality.h"
#include "client/cli/exit_status.h"
#include "client/cli/sample_source.h"
#include "evaluation/discrepancy.h"

namespace sfc {
namespace {

struct EvalFlags {
  std::string setting = "fast";
  int l_min = 0, l_max = 0;
  std::vector<std::string> plane, sphere;
  std::string out_dir = "eval-out";
  uint64_t seed = 1;
  std::string model;  // model mode: a sphere-shaped model spec against the built-in sphere
  int seeds = 2;
  EvalQualityFlags quality;
  ConnectionFlags connection;
};

// The whole set of `count` samples (seed `seed`) of the surface and density.
absl::StatusOr<SampleBatch> WholeSet(SampleSource& source, const std::string& surface,
                                     const std::string& density, uint64_t count, uint64_t seed,
                                     SequenceKind sequence = SequenceKind::kJittered) {
  SampleRequest request;
  request.sequence = sequence;
  request.tree.surface = surface;
  request.tree.density = density;
  request.count = count;
  request.seed = seed;
  return CollectSamples(source, request);
}

// Model mode (issue 11): the spherical-triangle discrepancy of a model that is
// a sphere (a STEP, IGES or NURBS sphere, or a mesh of one) against the
// built-in sphere, N = 64 .. 24576, the mean over `seeds` seeds, and both
// slopes. Points are projected onto the unit sphere about the centre of their
// bounding box; the model's own deviation from a sphere shows as
// discrepancy.
int RunEvalModel(const EvalFlags& f, SampleSource& source) {
  auto discrepancy = [&](const std::string& surface, uint64_t n,
                         uint64_t seed) -> absl::StatusOr<double> {
    ASSIGN_OR_RETURN(const SampleBatch all, WholeSet(source, surface, "uniform", n, seed));
    Vec3 lo{INFINITY, INFINITY, INFINITY}, hi{-INFINITY, -INFINITY, -INFINITY};
    for (size_t i = 0; i < all.size(); ++i) {
      lo = {std::min(lo.x, all.x[i]), std::min(lo.y, all.y[i]), std::min(lo.z, all.z[i])};
      hi = {std::max(hi.x, all.x[i]), std::max(hi.y, all.y[i]), std::max(hi.z, all.z[i])};
    }
    const Vec3 centre = (lo + hi) * 0.5;
    std::vector<Vec3> points;
    for (size_t i = 0; i < all.size(); ++i) {
      const Vec3 d = Vec3{all.x[i], all.y[i], all.z[i]} - centre;
      points.push_back(d * (1 / Norm(d)));
    }
    return SphericalTriangleDiscrepancy(points);
  };
  std::vector<double> ns, model_d, sphere_d;
  std::printf(
      "spherical-triangle discrepancy, mean of %d seeds\n\n| N | %s | built-in sphere |\n"
      "|---:|---:|---:|\n",
      f.seeds, f.model.c_str());
  for (int l = 6; l <= 14; ++l) {
    for (uint64_t n : {uint64_t{1} << l, (uint64_t{3} << l) / 2}) {
      if (n > 24576) continue;
      double dm = 0, ds = 0;
      for (int i = 0; i < f.seeds; ++i) {
        auto m = discrepancy(f.model, n, f.seed + i);
        if (!m.ok()) return Fail(m.status());
        auto b = discrepancy("sphere", n, f.seed + i);
        if (!b.ok()) return Fail(b.status());
        dm += *m / f.seeds, ds += *b / f.seeds;
      }
      ns.push_back(n), model_d.push_back(dm), sphere_d.push_back(ds);
      std::printf("| %llu | %.4g | %.4g |\n", static_cast<unsigned long long>(n), dm, ds);
    }
  }
  std::printf("| slope | **%.3f** | %.3f |\n", LogLogSlope(ns, model_d), LogLogSlope(ns, sphere_d));
  return 0;
}

int RunEval(const EvalFlags& f) {
  if (f.model.empty() && f.setting != "fast" && f.setting != "full") {
    return Fail(absl::InvalidArgumentError("--setting must be fast or full"));
  }
  auto opened = OpenSampleSource(f.connection);
  if (!opened.ok()) return Fail(opened.status());
  const std::unique_ptr<SampleSource> source = *std::move(opened);
  if (!f.model.empty()) return RunEvalModel(f, *source);
  if (WantsSection(f.quality, "quality")) {
    // Every set of the report in full.
    auto sets = [&source](const std::string& surface, const std::string& density, uint64_t count,
                          uint64_t seed, SequenceKind sequence) {
      return WholeSet(*source, surface, density, count, seed, sequence);
    };
    if (const int rc = RunEvalQuality(f.quality, f.setting == "full", f.out_dir, sets); rc != 0)
      return rc;
  }
  if (!WantsSection(f.quality, "protocol")) return 0;
  ProtocolOptions options;
  if (f.setting == "full") options.l_max = 20;  // the paper: 40 sizes, 2 to 2^20 + 2^19 = 1572864
  if (f.l_min) options.l_min = f.l_min;
  if (f.l_max) options.l_max = f.l_max;
  options.plane_methods = f.plane;
  options.sphere_methods = f.sphere;
  options.seed = f.seed;
  // In process RunProtocol makes our sets itself.
  return RunEvalProtocol(options, f.out_dir, f.connection.server.empty() ? nullptr : source.get());
}

}  // namespace

Command AddEvalCommand(CLI::App& app) {
  auto flags = std::make_shared<EvalFlags>();
  EvalFlags& f = *flags;
  CLI::App* eval = app.add_subcommand(
      "eval", "run the paper's discrepancy protocol and compare slopes with Tables 1-2");
  eval->add_option("--setting", f.setting,
                   "fast (N up to 12288, seconds) or full (the paper's 2 to 1572864, minutes)")
      ->capture_default_str();
  eval->add_option("--l-min", f.l_min, "smallest l (N = 2^l and 2^l + 2^(l-1))");
  eval->add_option("--l-max", f.l_max, "largest l");
  eval->add_option("--plane-methods", f.plane,
                   "subset of: random jittered2d sobol halton hammersley hilbert-jittered "
                   "hilbert2-jittered peano-jittered")
      ->delimiter(',');
  eval->add_option("--sphere-methods", f.sphere,
                   "subset of: random hammersley fibonacci hilbert-jittered-fff "
                   "hilbert-jittered-triangle hilbert-jittered-quadrature")
      ->delimiter(',');
  eval->add_option("--out-dir", f.out_dir, "where the CSV, the slope tables and the plots go")
      ->capture_default_str();
  eval->add_option("--seed", f.seed, "seed of the random and jittered sets")->capture_default_str();
  eval->add_option("--model", f.model,
                   "model mode: a sphere-shaped model (step:sphere.step, ply:icosphere.ply, ...) "
                   "against the built-in sphere, spherical-triangle discrepancy, N = 64..24576");
  eval->add_option("--seeds", f.seeds, "model mode: seeds averaged per N")->capture_default_str();
  AddEvalQualityFlags(eval, &f.quality);
  AddConnectionFlags(eval, &f.connection);
  return {eval, [flags] { return RunEval(*flags); }};
}

}  // namespace sfc
