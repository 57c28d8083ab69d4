#include "client/cli/eval_quality.h"

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>

#include "absl/strings/str_format.h"

namespace sfc {

void AddEvalQualityFlags(CLI::App* eval, EvalQualityFlags* f) {
  eval->add_option("--sections", f->sections,
                   "protocol (the paper's Tables 1-2) and/or quality (issue 19: sample-anchored "
                   "boxes, strips, "
                   "Monte Carlo, plane, sphere, models, blue noise; issue 33: generic "
                   "features; issue 36: integration)")
      ->delimiter(',')
      ->capture_default_str();
  eval->add_option("--quality-sections", f->quality_sections,
                   "subset of: boxes strips bands mc plane sphere models blue features "
                   "integration (default all but integration, which times its runs)")
      ->delimiter(',');
  eval->add_option("--quality-seeds", f->seeds,
                   "seeds of the quality report's slopes and Monte Carlo (>= 3)")
      ->delimiter(',')
      ->capture_default_str();
  eval->add_option(
      "--step-sphere", f->step_sphere,
      "quality: a CAD sphere to compare with the built-in (e.g. step:/tmp/fx/sphere.step from "
      "build/cad/make_cad_fixtures /tmp/fx)");
  eval->add_option(
      "--mesh-sphere", f->mesh_sphere,
      "quality: a sphere mesh to compare with the built-in (e.g. ply:/tmp/ico.ply from "
      "bench/eval_quality.sh)");
}

bool WantsSection(const EvalQualityFlags& flags, const std::string& section) {
  return std::find(flags.sections.begin(), flags.sections.end(), section) != flags.sections.end();
}

int RunEvalQuality(const EvalQualityFlags& flags, bool full, const std::string& out_dir,
                   const QualitySource& source) {
  QualityOptions options;
  options.full = full;
  options.seeds = flags.seeds;
  options.sections = flags.quality_sections;
  options.step_sphere = flags.step_sphere;
  options.mesh_sphere = flags.mesh_sphere;
  options.out_dir = out_dir;
  const auto start = std::chrono::steady_clock::now();
  options.progress = [&](const std::string& line) {
    std::fprintf(stderr, "quality: %s (%.0f s)\n", line.c_str(),
                 std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  };
  auto report = RunQuality(options, source);
  if (!report.ok()) {
    std::fprintf(stderr, "error: %s\n", std::string(report.status().message()).c_str());
    return 1;
  }
  const std::string text =
      absl::StrFormat("# Quality report (issue 19), setting %s\n\n%s## Summary\n\n%s",
                      full ? "full" : "fast", report->tables, QualitySummary(report->checks));
  std::printf("%s\n", text.c_str());
  std::error_code ec;
  std::filesystem::create_directories(out_dir, ec);
  std::FILE* out = std::fopen((out_dir + "/quality.md").c_str(), "w");
  if (!out || std::fputs(text.c_str(), out) < 0 || std::fclose(out) != 0) {
    std::fprintf(stderr, "error: cannot write %s/quality.md\n", out_dir.c_str());
    return 1;
  }
  for (const auto& [name, svg] : report->pictures) {
    const std::string path = out_dir + "/" + name;
    std::FILE* picture = std::fopen(path.c_str(), "w");
    if (!picture || std::fputs(svg.c_str(), picture) < 0 || std::fclose(picture) != 0) {
      std::fprintf(stderr, "error: cannot write %s\n", path.c_str());
      return 1;
    }
  }
  std::fprintf(stderr, "wrote %s/quality.md and %d pictures\n", out_dir.c_str(),
               static_cast<int>(report->pictures.size()));
  return 0;
}

}  // namespace sfc
