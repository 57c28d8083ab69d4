#include "evaluation/reference_measure.h"

#include <cmath>

#include "absl/strings/str_format.h"
#include "core/area_estimator.h"

namespace sfc {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Gauss-Legendre nodes and weights on [0,1] by Newton's method on P_n.
void GaussLegendre(int n, std::vector<double>* x, std::vector<double>* w) {
  x->resize(n);
  w->resize(n);
  for (int i = 0; i < n; ++i) {
    double z = std::cos(kPi * (i + 0.75) / (n + 0.5)), dp = 0;
    for (int it = 0; it < 100; ++it) {
      double p0 = 1, p1 = z;
      for (int k = 2; k <= n; ++k) {
        const double p2 = ((2 * k - 1) * z * p1 - (k - 1) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      if (n == 1) p1 = z, p0 = 1;
      dp = n * (z * p1 - p0) / (z * z - 1);
      const double step = p1 / dp;
      z -= step;
      if (std::fabs(step) < 1e-16) break;
    }
    (*x)[i] = (1 - z) / 2;
    (*w)[i] = 1 / ((1 - z * z) * dp * dp);  // 2 / ((1-z^2) P'^2), halved for [0,1]
  }
}

}  // namespace

absl::StatusOr<std::vector<double>> GradedCellMasses(const Surface& surface, const Density& density,
                                                     int grid, int nodes) {
  if (grid < 1 || nodes < 1 || nodes > 16) {
    return absl::InvalidArgumentError("GradedCellMasses needs grid >= 1 and 1 <= nodes <= 16");
  }
  std::vector<double> s, ws;
  GaussLegendre(nodes, &s, &ws);
  // The graded nodes inside a unit cell: q(s) and weight w q'(s).
  std::vector<double> q(nodes), wq(nodes);
  for (int k = 0; k < nodes; ++k) {
    const double a = s[k], b = 1 - s[k];
    q[k] = a * a * a * (10 - 15 * a + 6 * a * a);
    wq[k] = ws[k] * 30 * a * a * b * b;
  }
  const bool curvature = density.NeedsCurvature();
  std::vector<double> masses(static_cast<size_t>(grid) * grid);
  const double h = 1.0 / grid;
  std::vector<double> us(nodes), vs(nodes);
  std::vector<SurfaceJet> jets(nodes * nodes);
  for (int i = 0; i < grid; ++i) {
    for (int k = 0; k < nodes; ++k) us[k] = (i + q[k]) * h;
    for (int j = 0; j < grid; ++j) {
      for (int k = 0; k < nodes; ++k) vs[k] = (j + q[k]) * h;
      surface.JetGrid(us.data(), nodes, vs.data(), nodes, curvature ? 2 : 1, jets.data());
      double sum = 0;
      for (int a = 0; a < nodes; ++a) {
        for (int b = 0; b < nodes; ++b) {
          const SurfaceJet& jet = jets[a * nodes + b];
          double area;
          const SurfacePoint point = PointFromJet(jet, us[a], vs[b], curvature, &area);
          const double delta = density.Value(point);
          const double m = delta * area;
          if (!std::isfinite(m) || delta < 0) {
            return absl::InvalidArgumentError(absl::StrFormat(
                "the reference measure is not finite at (u,v) = (%.17g, %.17g)", us[a], vs[b]));
          }
          sum += wq[a] * wq[b] * m;
        }
      }
      masses[static_cast<size_t>(i) * grid + j] = sum * h * h;
    }
  }
  return masses;
}

}  // namespace sfc
