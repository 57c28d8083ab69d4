// `sfcsampler render`: draws a PNG of the samples (on the surface or in the
// parameter square), in process or from --server, or of the adaptive curve
// tree itself (in process only: the tree does not travel).
#include <cstdio>
#include <memory>
#include <string>

#include "base/status_macros.h"
#include "catalog/catalog.h"
#include "client/cli/commands.h"
#include "client/cli/connection_flags.h"
#include "client/cli/exit_status.h"
#include "client/cli/in_process_sample_source.h"
#include "client/cli/sample_source.h"
#include "render/render.h"
#include "request/request_flags.h"

namespace sfc {
namespace {

struct RenderFlags {
  RequestFlags request;
  std::string what = "samples";
  std::string view = "35,25";
  int size = 900;
  std::string title;
  std::string output = "render.png";
  ConnectionFlags connection;
};

// --what curve or param-curve: the tree drawn, built in process (the wire
// carries samples, not trees).
absl::Status DrawCurve(const RenderFlags& r, const SampleRequest& request, const View& view) {
  if (!r.connection.server.empty()) {
    return absl::FailedPreconditionError(
        "--what curve and param-curve draw the curve tree, which stays on the server; run them "
        "without --server (the tree is the same), or draw samples");
  }
  InProcessSampleSource local(SampleSourceOptions{});
  ASSIGN_OR_RETURN(SamplingJob job, local.engine().Start(request));
  const std::shared_ptr<const CurveTree> curve_tree = TreeAs<CurveTree>(job.tree.lookup.any.get());
  if (!curve_tree) {
    return absl::InvalidArgumentError(
        "--what curve and param-curve draw a parameter-square curve tree; a mesh has none: "
        "draw its samples (--what samples)");
  }
  const CurveTree& tree = *curve_tree;
  // The surface its tree is over (a formula surface: the only kind with a CurveTree here).
  ASSIGN_OR_RETURN(const SurfaceFromSpec surface, MakeSurface(request.tree.surface));
  RETURN_IF_ERROR(r.what == "curve" ? RenderCurve(tree, *surface.surface, view, r.output)
                                    : RenderParameterCurve(tree, view, r.output));
  std::fprintf(stderr, "wrote %s (%s, %zu leaves)\n", r.output.c_str(), r.what.c_str(),
               tree.leaf_count());
  return absl::OkStatus();
}

// --what samples or param-samples: the whole set drawn, in process or from
// --server.
absl::Status DrawSamples(const RenderFlags& r, const SampleRequest& request, const View& view) {
  ASSIGN_OR_RETURN(const std::unique_ptr<SampleSource> source, OpenSampleSource(r.connection));
  SampleBatch all;
  Progress progress(true);
  ASSIGN_OR_RETURN(const std::string provenance,
                   source->Sample(
                       request, &progress,
                       [](const TreeReport& tree) {
                         PrintTreeSummary(tree, Verbosity{true, false});
                       },
                       [&all](std::optional<uint64_t>, const SampleBatch& batch) {
                         all.Append(batch);
                         return absl::OkStatus();
                       }));
  RETURN_IF_ERROR(r.what == "samples" ? RenderSamples(all, view, r.output)
                                      : RenderParameterSamples(all, view, r.output));
  std::fprintf(stderr, "wrote %s (%s, %zu samples %s)\n", r.output.c_str(), r.what.c_str(),
               all.size(), provenance.c_str());
  return absl::OkStatus();
}

int RunRender(const RenderFlags& r) {
  auto request = ToSampleRequest(r.request);
  if (!request.ok()) return Fail(request.status());
  View view;
  view.width = view.height = r.size;
  view.title = r.title;
  if (std::sscanf(r.view.c_str(), "%lf,%lf", &view.azimuth_degrees, &view.elevation_degrees) != 2) {
    return Fail(
        absl::InvalidArgumentError("--view takes AZIMUTH,ELEVATION in degrees, e.g. 35,25"));
  }
  request->fields.normal = true;
  absl::Status status;
  if (r.what == "curve" || r.what == "param-curve") {
    status = DrawCurve(r, *request, view);
  } else if (r.what == "samples" || r.what == "param-samples") {
    status = DrawSamples(r, *request, view);
  } else {
    status =
        absl::InvalidArgumentError("--what must be samples, curve, param-samples or param-curve");
  }
  return status.ok() ? 0 : Fail(status);
}

}  // namespace

Command AddRenderCommand(CLI::App& app) {
  auto flags = std::make_shared<RenderFlags>();
  CLI::App* render = app.add_subcommand("render", "draw samples or the adaptive curve as a PNG");
  AddTreeFlags(render, &flags->request);
  AddSampleFlags(render, &flags->request);
  render->add_option("--what", flags->what, "samples | curve | param-samples | param-curve")
      ->capture_default_str();
  render->add_option("--view", flags->view, "AZIMUTH,ELEVATION in degrees")->capture_default_str();
  render->add_option("--size", flags->size, "picture width and height in pixels")
      ->capture_default_str();
  render->add_option("--title", flags->title, "caption");
  render->add_option("--output,-o", flags->output, "PNG file")->capture_default_str();
  AddConnectionFlags(render, &flags->connection);
  return {render, [flags] { return RunRender(*flags); }};
}

}  // namespace sfc
