#include "evaluation/reference_measure.h"

#include <cmath>

#include "absl/strings/str_format.h"
#include "core/area_estimator.h"
#include "evaluation/gauss_legendre.h"

namespace sfc {

absl::StatusOr<std::vector<double>> GradedCellMasses(const Surface& surface, const Density& density,
                                                     int grid, int nodes) {
  if (grid < 1 || nodes < 1 || nodes > 16) {
    return absl::InvalidArgumentError("GradedCellMasses needs grid >= 1 and 1 <= nodes <= 16");
  }
  const GaussRule& rule = GaussLegendreRule(nodes);
  const std::vector<double>& s = rule.x;
  const std::vector<double>& ws = rule.w;
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
