// Measures the area x density estimators (paper Sect. 3 (a), (b), (c) and the
// cell quadrature) against exact integrals, and prints a table:
//  - the relative error of the total mass S_M against the exact integral;
//  - the worst |count - N * exact cell mass| over an 8 x 8 grid of parameter
//    cells for N jittered-Hilbert samples (2 is the bound jittering promises
//    for an exact estimator, for cells of the curve's own subdivision).
// Usage: estimator_accuracy [N]   (default 100000)
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <memory>
#include <string>

#include "catalog/catalog.h"
#include "core/sampler.h"

namespace sfc {
namespace {

constexpr double kPi = 3.14159265358979323846;

struct Case {
  const char* surface;
  const char* density;
  double total;  // exact int delta dS
  std::function<double(double, double, double, double)> cell;  // exact over [a,b]x[c,d]
};

int Run(uint64_t n) {
  const Case cases[] = {
      {"sphere", "uniform", 4 * kPi,
       [](double a, double b, double c, double d) {
         return (std::cos(kPi * a) - std::cos(kPi * b)) * 2 * kPi * (d - c);
       }},
      {"torus:R=1;r=0.4", "uniform", 4 * kPi * kPi * 0.4,
       [](double a, double b, double c, double d) {
         // dA = 4 pi^2 r (R + r cos(2 pi v)) du dv
         const double r = 0.4;
         return 4 * kPi * kPi * r *
                ((b - a) *
                 ((d - c) + r * (std::sin(2 * kPi * d) - std::sin(2 * kPi * c)) / (2 * kPi)));
       }},
      {"plane", "expr:u+v", 1.0,
       [](double a, double b, double c, double d) {
         return (b - a) * (d - c) * ((a + b) + (c + d)) / 2;
       }},
  };
  std::printf("N = %llu jittered Hilbert samples, grade-%d trees, rho = 1\n\n",
              static_cast<unsigned long long>(n), CurveTree::GradeFor(n));
  std::printf(
      "| surface | density | estimator | leaves | rel. error of S_M | worst cell |count - "
      "expected| |\n");
  std::printf("|---|---|---|---:|---:|---:|\n");
  for (const Case& c : cases) {
    auto surface = MakeSurface(c.surface);
    auto density = MakeDensity(c.density);
    for (AreaEstimator e : {AreaEstimator::kTriangle, AreaEstimator::kSquare,
                            AreaEstimator::kFirstFundamentalForm, AreaEstimator::kQuadrature}) {
      CurveTreeOptions options;
      options.estimator = e;
      auto tree =
          CurveTree::Build(*surface->surface, *density->density, options, CurveTree::GradeFor(n));
      if (!tree.ok()) {
        std::fprintf(stderr, "%s\n", tree.status().ToString().c_str());
        return 1;
      }
      auto sampler = std::make_shared<const Sampler>(*tree, surface->surface, density->density,
                                                     Sequence(SequenceKind::kJittered, n, 1));
      auto cursor = *SampleCursor::Create(sampler, 0, n, {}, {});
      SampleBatch b;
      while (*cursor->Next(1 << 16, &b) > 0) {
      }
      constexpr int kSide = 8;
      int counts[kSide][kSide] = {};
      for (size_t i = 0; i < b.size(); ++i) {
        ++counts[std::min(kSide - 1, static_cast<int>(b.u[i] * kSide))]
                [std::min(kSide - 1, static_cast<int>(b.v[i] * kSide))];
      }
      double worst = 0;
      for (int i = 0; i < kSide; ++i) {
        for (int j = 0; j < kSide; ++j) {
          const double h = 1.0 / kSide;
          const double expected = n * c.cell(i * h, (i + 1) * h, j * h, (j + 1) * h) / c.total;
          worst = std::max(worst, std::fabs(counts[i][j] - expected));
        }
      }
      std::printf("| %s | %s | %s | %zu | %.2e | %.2f |\n", c.surface, c.density,
                  std::string(AreaEstimatorName(e)).c_str(), (*tree)->leaf_count(),
                  std::fabs((*tree)->total_mass() - c.total) / c.total, worst);
    }
  }
  return 0;
}

}  // namespace
}  // namespace sfc

int main(int argc, char** argv) {
  return sfc::Run(argc > 1 ? std::strtoull(argv[1], nullptr, 10) : 100000);
}
