// `sfcsampler surfaces`: lists the catalogue's surfaces and densities with
// their formulas and parameters, and the curves, sequences and estimators,
// on stdout.
#include <cstdio>
#include <vector>

#include "catalog/catalog.h"
#include "client/cli/commands.h"

namespace sfc {
namespace {

void PrintCatalog(const char* title, const std::vector<CatalogEntry>& entries) {
  std::printf("%s\n", title);
  for (const CatalogEntry& e : entries) {
    std::printf("  %-15s %s\n  %-15s   %s\n", e.name.c_str(), e.description.c_str(), "",
                e.formula.c_str());
    for (const CatalogParameter& p : e.parameters) {
      std::printf("  %-15s   %s=%s  %s\n", "", p.name.c_str(),
                  p.default_value.empty() ? "(required)" : p.default_value.c_str(),
                  p.meaning.c_str());
    }
  }
}

int RunSurfaces() {
  PrintCatalog("surfaces (--surface NAME[:KEY=VALUE;...]):", SurfaceCatalog());
  PrintCatalog("\ndensities (--density NAME[:KEY=VALUE;...] or expr:EXPRESSION):",
               DensityCatalog());
  std::printf(
      "\ncurves (--curve): hilbert (2x2), hilbert2 (3x3 meander), peano (3x3 serpentine)\n");
  std::printf(
      "sequences (--sequence): jittered (default), equal, random, vandercorput, progressive, "
      "blue, sobol\n");
  std::printf("estimators (--estimator): triangle (a), square (b), fff (c, default), quadrature\n");
  return 0;
}

}  // namespace

Command AddSurfacesCommand(CLI::App& app) {
  CLI::App* surfaces = app.add_subcommand(
      "surfaces", "list the surfaces, densities, curves and sequences with their formulas");
  return {surfaces, RunSurfaces};
}

}  // namespace sfc
