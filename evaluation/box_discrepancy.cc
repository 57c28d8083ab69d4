#include "evaluation/box_discrepancy.h"

#include <algorithm>
#include <cmath>
#include <random>

#include "absl/strings/str_format.h"
#include "core/area_estimator.h"
#include "evaluation/gauss_legendre.h"

namespace sfc {
namespace {

constexpr int kRegularNodes = 6;   // per axis in a cell off the lines
constexpr int kSingularNodes = 12; // per axis in a cell touching a line
constexpr int kPower = 12;         // x = line + h w^12 in such a cell
constexpr double kGradeStart = 1.0 / 16, kGradeRatio = 0.25, kGradeEnd = 1e-11;

// delta |f_u x f_v| at (u, v) from the jet; the point, normal and curvatures
// only when the density reads them.
double MassDensity(const Density& density, bool curvature, const SurfaceJet& jet, double u,
                   double v) {
  if (curvature) {
    double area;
    const SurfacePoint p = PointFromJet(jet, u, v, true, &area);
    return density.Value(p) * area;
  }
  SurfacePoint p;
  p.u = u, p.v = v, p.p = jet.p;
  return density.Value(p) * Norm(Cross(jet.fu, jet.fv));
}

// Distance from [a, b] to the nearest line, and which end is nearer; 0 when
// the cell touches a line.
double NearDistance(double a, double b, const std::vector<double>& lines, double* line,
                    bool* at_left) {
  double best = INFINITY;
  for (double l : lines) {
    const double d = l <= a ? a - l : l >= b ? l - b : 0;
    if (d < best) best = d, *line = l, *at_left = l <= a;
  }
  return best;
}

// The sorted, graded breakpoints of one axis.
std::vector<double> Breakpoints(std::vector<double> x, const std::vector<double>& lines,
                                int background) {
  x.push_back(0);
  x.push_back(1);
  for (int k = 1; k < background; ++k) x.push_back(static_cast<double>(k) / background);
  for (double l : lines) {
    x.push_back(l);
    for (double d = kGradeStart; d >= kGradeEnd; d *= kGradeRatio) {
      if (l - d > 0) x.push_back(l - d);
      if (l + d < 1) x.push_back(l + d);
    }
  }
  for (double& c : x) c = std::clamp(c, 0.0, 1.0);
  std::sort(x.begin(), x.end());
  x.erase(std::unique(x.begin(), x.end()), x.end());
  // Split every cell off a line that spans more than a factor 4 of distance.
  std::vector<double> extra;
  for (size_t i = 0; i + 1 < x.size(); ++i) {
    double line = 0;
    bool at_left = true;
    const double d1 = NearDistance(x[i], x[i + 1], lines, &line, &at_left);
    if (d1 == 0 || !std::isfinite(d1)) continue;
    const double d2 = d1 + (x[i + 1] - x[i]);
    for (double d = 4 * d1; d < d2; d *= 4) extra.push_back(at_left ? line + d : line - d);
  }
  x.insert(x.end(), extra.begin(), extra.end());
  std::sort(x.begin(), x.end());
  x.erase(std::unique(x.begin(), x.end()), x.end());
  return x;
}

// Quadrature nodes and weights of one cell. Beside a line at c != 0 a
// parameter cannot come closer to it than an ulp of c, and the surface's
// angle loses the distance below ~1e-16 anyway, so nodes closer than t_min =
// 4096 ulp(c) are evaluated at c +- t_min and scaled by (t / t_min)^alpha,
// alpha measured between t_min and 4 t_min at the same node (the local
// exponent of the line; this touches only the innermost ~1e-11 of it).
struct CellRule {
  double x[16], w[16];
  double ratio[16];  // t / t_min for a moved node, 1 otherwise
  double probe = 0;  // c +- 4 t_min
  int n = 0;
  bool moved = false;
};
CellRule RuleFor(double a, double b, const std::vector<double>& lines) {
  CellRule r;
  double line = 0;
  bool at_left = true;
  const double d = NearDistance(a, b, lines, &line, &at_left);
  const double h = b - a;
  std::fill(r.ratio, r.ratio + 16, 1.0);
  if (d == 0) {
    const GaussRule& g = GaussLegendreRule(kSingularNodes);
    r.n = kSingularNodes;
    const double t_min = line == 0 ? 0 : 4096 * (std::nextafter(line, 2.0) - line);
    const double side = at_left ? 1 : -1;
    r.probe = line + side * 4 * t_min;
    for (int k = 0; k < r.n; ++k) {
      const double w = g.x[k], wm1 = std::pow(w, kPower - 1);
      const double t = h * wm1 * w;
      r.x[k] = line + side * t;
      if (t < t_min) r.x[k] = line + side * t_min, r.ratio[k] = t / t_min, r.moved = true;
      r.w[k] = g.w[k] * kPower * wm1 * h;
    }
  } else {
    // Gauss on [d, d + h] of t^alpha converges like rho^(-2n), rho from the
    // ellipse that reaches t = 0: for h = 3d (the grading's widest cell)
    // rho = 3 and 6 nodes leave 2e-6 of the cell; 12 nodes 4e-12.
    const int nodes = h > 0.25 * d ? kSingularNodes : kRegularNodes;
    const GaussRule& g = GaussLegendreRule(nodes);
    r.n = nodes;
    for (int k = 0; k < r.n; ++k) r.x[k] = a + h * g.x[k], r.w[k] = g.w[k] * h;
  }
  return r;
}

}  // namespace

absl::StatusOr<SingularLines> DetectSingularLines(const Surface& surface, const Density& density) {
  std::vector<double> candidates;
  for (int k = 0; k <= 1024; ++k) candidates.push_back(k / 1024.0);
  for (int k = 0; k <= 12; ++k) candidates.push_back(k / 12.0);
  for (int k = 0; k <= 10; ++k) candidates.push_back(k / 10.0);
  std::sort(candidates.begin(), candidates.end());
  candidates.erase(std::unique(candidates.begin(), candidates.end()), candidates.end());
  const bool curvature = density.NeedsCurvature();
  auto m = [&](double u, double v) {
    const SurfaceJet jet = surface.Jet(u, v, curvature ? 2 : 1);
    return MassDensity(density, curvature, jet, u, v);
  };
  SingularLines out;
  for (int axis = 0; axis < 2; ++axis) {
    for (double c : candidates) {
      bool singular = false;
      for (int side : {-1, 1}) {
        if (c + side * 1e-3 < 0 || c + side * 1e-3 > 1) continue;
        int flagged = 0;
        for (int j = 0; j < 7; ++j) {
          const double t = (j + 0.37) / 7;
          auto at = [&](double d) { return axis == 0 ? m(c + side * d, t) : m(t, c + side * d); };
          const double m7 = at(1e-7), m5 = at(1e-5), m3 = at(1e-3);
          // The local exponent on two scales; a line further than ~1e-5
          // away (a neighbouring candidate's) shows on one scale only.
          const double fine = std::log(m7 / m5) / std::log(1e-2),
                       coarse = std::log(m5 / m3) / std::log(1e-2);
          if (!std::isfinite(fine) || !std::isfinite(coarse)) continue;
          if (std::fabs(fine) > 0.1 && std::fabs(coarse) > 0.1 && fine * coarse > 0 &&
              std::fabs(fine - coarse) < 0.5 * std::max(std::fabs(fine), std::fabs(coarse))) {
            ++flagged;
          }
        }
        singular = singular || flagged >= 6;
      }
      if (singular) (axis == 0 ? out.u : out.v).push_back(c);
    }
  }
  return out;
}

absl::StatusOr<GradedBoxMeasure> GradedBoxMeasure::Build(
    const Surface& surface, const Density& density, const SingularLines& lines,
    std::vector<double> u_breaks, std::vector<double> v_breaks, int background) {
  GradedBoxMeasure g;
  g.u_ = Breakpoints(std::move(u_breaks), lines.u, background);
  g.v_ = Breakpoints(std::move(v_breaks), lines.v, background);
  const size_t nu = g.u_.size() - 1, nv = g.v_.size() - 1;
  std::vector<CellRule> ru(nu), rv(nv);
  for (size_t i = 0; i < nu; ++i) ru[i] = RuleFor(g.u_[i], g.u_[i + 1], lines.u);
  for (size_t j = 0; j < nv; ++j) rv[j] = RuleFor(g.v_[j], g.v_[j + 1], lines.v);
  const bool curvature = density.NeedsCurvature();
  g.prefix_.assign((nu + 1) * (nv + 1), 0.0);
  auto at = [&](size_t i, size_t j) -> double& { return g.prefix_[i * (nv + 1) + j]; };
  SurfaceJet jets[16 * 16];
  for (size_t i = 0; i < nu; ++i) {
    const CellRule& a = ru[i];
    for (size_t j = 0; j < nv; ++j) {
      const CellRule& b = rv[j];
      surface.JetGrid(a.x, a.n, b.x, b.n, curvature ? 2 : 1, jets);
      double sum = 0;
      for (int p = 0; p < a.n; ++p) {
        double row = 0;
        for (int q = 0; q < b.n; ++q) {
          double m = MassDensity(density, curvature, jets[p * b.n + q], a.x[p], b.x[q]);
          if (a.ratio[p] != 1 || b.ratio[q] != 1) {
            auto at_point = [&](double u, double v) {
              return MassDensity(density, curvature, surface.Jet(u, v, curvature ? 2 : 1), u, v);
            };
            const double m0 = m;
            if (a.ratio[p] != 1) {
              m *= std::pow(a.ratio[p], std::log(at_point(a.probe, b.x[q]) / m0) / std::log(4.0));
            }
            if (b.ratio[q] != 1) {
              m *= std::pow(b.ratio[q], std::log(at_point(a.x[p], b.probe) / m0) / std::log(4.0));
            }
          }
          if (!std::isfinite(m) || m < 0) {
            return absl::InvalidArgumentError(absl::StrFormat(
                "the reference measure is %g at (u,v) = (%.17g, %.17g)", m, a.x[p], b.x[q]));
          }
          row += b.w[q] * m;
        }
        sum += a.w[p] * row;
      }
      at(i + 1, j + 1) = sum;
    }
  }
  for (size_t i = 1; i <= nu; ++i) {
    for (size_t j = 1; j <= nv; ++j) at(i, j) += at(i - 1, j) + at(i, j - 1) - at(i - 1, j - 1);
  }
  return g;
}

double GradedBoxMeasure::Mass(size_t i0, size_t i1, size_t j0, size_t j1) const {
  const size_t w = v_.size();
  return prefix_[i1 * w + j1] - prefix_[i0 * w + j1] - prefix_[i1 * w + j0] + prefix_[i0 * w + j0];
}

size_t GradedBoxMeasure::UIndex(double x) const {
  return std::lower_bound(u_.begin(), u_.end(), x) - u_.begin();
}
size_t GradedBoxMeasure::VIndex(double x) const {
  return std::lower_bound(v_.begin(), v_.end(), x) - v_.begin();
}

absl::StatusOr<BoxDiscrepancy> SampleAnchoredBoxDiscrepancy(const Surface& surface,
                                                            const Density& density,
                                                            const SingularLines& lines,
                                                            const std::vector<Point2>& uv,
                                                            const BoxDiscrepancyOptions& options) {
  const size_t n = uv.size();
  if (n == 0) return absl::InvalidArgumentError("no points");
  std::mt19937_64 rng(options.seed * 0x9E3779B97F4A7C15ull + 19);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  std::vector<double> us(n), vs(n);
  for (size_t i = 0; i < n; ++i) us[i] = uv[i].x, vs[i] = uv[i].y;
  std::sort(us.begin(), us.end());
  std::sort(vs.begin(), vs.end());
  auto corners = [&](const std::vector<double>& sorted) {
    std::vector<double> c;
    const int k = options.sample_corners;
    const double offset = uniform(rng);
    for (int i = 0; i < k; ++i) {
      const size_t rank = std::min(n - 1, static_cast<size_t>((i + offset) * n / k));
      c.push_back(sorted[rank]);
      c.push_back(std::nextafter(sorted[rank], 2.0));
    }
    for (int i = 0; i < options.random_corners; ++i) c.push_back(uniform(rng));
    return c;
  };
  std::vector<double> cu = corners(us), cv = corners(vs);
  auto measure = GradedBoxMeasure::Build(surface, density, lines, std::move(cu), std::move(cv),
                                         options.background);
  if (!measure.ok()) return measure.status();
  const std::vector<double>& bu = measure->u();
  const std::vector<double>& bv = measure->v();
  const size_t nu = bu.size() - 1, nv = bv.size() - 1;
  // Counts per cell [bu_i, bu_i+1) x [bv_j, bv_j+1), then prefix sums.
  std::vector<int64_t> count((nu + 1) * (nv + 1), 0);
  auto c_at = [&](size_t i, size_t j) -> int64_t& { return count[i * (nv + 1) + j]; };
  for (const Point2& p : uv) {
    const size_t i = std::min(
        nu - 1, static_cast<size_t>(std::upper_bound(bu.begin(), bu.end(), p.x) - bu.begin()) - 1);
    const size_t j = std::min(
        nv - 1, static_cast<size_t>(std::upper_bound(bv.begin(), bv.end(), p.y) - bv.begin()) - 1);
    ++c_at(i + 1, j + 1);
  }
  for (size_t i = 1; i <= nu; ++i) {
    for (size_t j = 1; j <= nv; ++j)
      c_at(i, j) += c_at(i - 1, j) + c_at(i, j - 1) - c_at(i - 1, j - 1);
  }
  const double total = measure->total();
  BoxDiscrepancy best;
  auto consider = [&](size_t i0, size_t i1, size_t j0, size_t j1) {
    const int64_t inside = c_at(i1, j1) - c_at(i0, j1) - c_at(i1, j0) + c_at(i0, j0);
    const double pf = static_cast<double>(inside) / n, mf = measure->Mass(i0, i1, j0, j1) / total;
    ++best.boxes;
    if (std::fabs(pf - mf) > best.d) {
      best.d = std::fabs(pf - mf);
      best.u0 = bu[i0], best.u1 = bu[i1], best.v0 = bv[j0], best.v1 = bv[j1];
      best.point_fraction = pf, best.mass_fraction = mf;
    }
  };
  for (size_t i = 0; i <= nu; ++i) {
    for (size_t j = 0; j <= nv; ++j) {
      consider(0, i, 0, j);
      consider(i, nu, 0, j);
      consider(0, i, j, nv);
      consider(i, nu, j, nv);
    }
  }
  std::uniform_int_distribution<size_t> pick_u(0, nu), pick_v(0, nv);
  for (int k = 0; k < options.random_boxes; ++k) {
    size_t i0 = pick_u(rng), i1 = pick_u(rng), j0 = pick_v(rng), j1 = pick_v(rng);
    if (i0 > i1) std::swap(i0, i1);
    if (j0 > j1) std::swap(j0, j1);
    consider(i0, i1, j0, j1);
  }
  return best;
}

}  // namespace sfc
