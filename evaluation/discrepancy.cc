#include "evaluation/discrepancy.h"

#include <algorithm>
#include <cmath>

#include "base/counter_hash.h"

namespace sfc {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Counts how many of the inserted values are < or <= a query, by rank.
class Fenwick {
 public:
  explicit Fenwick(size_t n) : tree_(n + 1, 0) {}
  void Add(size_t i) {
    for (++i; i < tree_.size(); i += i & (~i + 1)) ++tree_[i];
  }
  // Sum of positions [0, i).
  int64_t Prefix(size_t i) const {
    int64_t s = 0;
    for (; i > 0; i -= i & (~i + 1)) s += tree_[i];
    return s;
  }

 private:
  std::vector<int64_t> tree_;
};

// K candidate values from the sorted coordinates (all if n <= k) plus 1.
std::vector<double> Corners(std::vector<double> sorted, int k) {
  std::vector<double> out;
  const size_t n = sorted.size();
  if (n <= static_cast<size_t>(k)) {
    out = sorted;
  } else {
    for (int i = 0; i < k; ++i) out.push_back(sorted[(static_cast<size_t>(i) * n) / k]);
  }
  out.push_back(1.0);
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

}  // namespace

double StarDiscrepancy(const std::vector<Point2>& points, int max_corners) {
  const size_t n = points.size();
  if (n == 0) return 0;
  std::vector<double> xs(n), ys(n);
  for (size_t i = 0; i < n; ++i) xs[i] = points[i].x, ys[i] = points[i].y;
  std::sort(xs.begin(), xs.end());
  std::vector<double> ys_sorted = ys;
  std::sort(ys_sorted.begin(), ys_sorted.end());
  const std::vector<double> a_corners = Corners(xs, max_corners);
  const std::vector<double> b_corners = Corners(ys_sorted, max_corners);

  std::vector<size_t> by_x(n);
  for (size_t i = 0; i < n; ++i) by_x[i] = i;
  std::sort(by_x.begin(), by_x.end(),
            [&](size_t a, size_t b) { return points[a].x < points[b].x; });
  auto y_rank = [&](size_t i) {
    return static_cast<size_t>(std::lower_bound(ys_sorted.begin(), ys_sorted.end(), points[i].y) -
                               ys_sorted.begin());
  };
  // For each b: the rank ranges of y < b and y <= b.
  std::vector<size_t> below(b_corners.size()), at_or_below(b_corners.size());
  for (size_t j = 0; j < b_corners.size(); ++j) {
    below[j] =
        std::lower_bound(ys_sorted.begin(), ys_sorted.end(), b_corners[j]) - ys_sorted.begin();
    at_or_below[j] =
        std::upper_bound(ys_sorted.begin(), ys_sorted.end(), b_corners[j]) - ys_sorted.begin();
  }
  Fenwick open(n), closed(n);  // points with x < a, and with x <= a
  size_t next_open = 0, next_closed = 0;
  double worst = 0;
  for (double a : a_corners) {
    while (next_open < n && points[by_x[next_open]].x < a) open.Add(y_rank(by_x[next_open++]));
    while (next_closed < n && points[by_x[next_closed]].x <= a)
      closed.Add(y_rank(by_x[next_closed++]));
    for (size_t j = 0; j < b_corners.size(); ++j) {
      const double area = a * b_corners[j];
      const double inside_open = static_cast<double>(open.Prefix(below[j])) / n;
      const double inside_closed = static_cast<double>(closed.Prefix(at_or_below[j])) / n;
      worst = std::max({worst, std::fabs(inside_open - area), std::fabs(inside_closed - area)});
    }
  }
  return worst;
}

double QuarterDiscArea(double r) {
  if (r <= 0) return 0;
  if (r <= 1) return kPi * r * r / 4;
  if (r >= std::sqrt(2.0)) return 1;
  return r * r * (kPi / 4 - std::acos(1 / r)) + std::sqrt(r * r - 1);
}

double QuarterDiscDiscrepancy(const std::vector<Point2>& points) {
  const size_t n = points.size();
  if (n == 0) return 0;
  std::vector<double> r(n);
  for (size_t i = 0; i < n; ++i) r[i] = std::hypot(points[i].x, points[i].y);
  std::sort(r.begin(), r.end());
  double worst = 0;
  // Just below r[i] the disc holds i points (fewer if ties); at r[i] it holds
  // every point up to the last tie.
  for (size_t i = 0; i < n; ++i) {
    const double area = QuarterDiscArea(r[i]);
    size_t j = i;
    while (j + 1 < n && r[j + 1] == r[i]) ++j;
    worst = std::max({worst, std::fabs(static_cast<double>(i) / n - area),
                      std::fabs(static_cast<double>(j + 1) / n - area)});
    i = j;
  }
  return std::max(worst, std::fabs(1.0 - QuarterDiscArea(std::sqrt(2.0))));
}

double AnchoredTriangleArea(double a, double b) {
  double area = a * b / 2;
  if (a > 1) area -= b * (a - 1) * (a - 1) / (2 * a);
  if (b > 1) area -= a * (b - 1) * (b - 1) / (2 * b);
  const double c = 1 - 1 / a - 1 / b;
  if (c > 0) area += a * b * c * c / 2;
  return area;
}

double TriangleDiscrepancy(const std::vector<Point2>& points, int grid) {
  const size_t n = points.size();
  if (n == 0) return 0;
  std::vector<double> values(grid);
  for (int i = 0; i < grid; ++i) values[i] = (i + 0.5) / grid * 2.5;
  std::vector<int64_t> histogram(grid + 1);
  double worst = 0;
  for (double a : values) {
    // A point with x < a lies inside iff t = y / (1 - x/a) < b.
    std::fill(histogram.begin(), histogram.end(), 0);
    for (const Point2& p : points) {
      if (p.x >= a) continue;
      const double t = p.y / (1 - p.x / a);
      // First grid value b with t < b: the point counts for it and all above.
      const size_t k = std::upper_bound(values.begin(), values.end(), t) - values.begin();
      ++histogram[k];
    }
    int64_t inside = 0;
    for (int j = 0; j < grid; ++j) {
      inside += histogram[j];
      worst = std::max(
          worst, std::fabs(static_cast<double>(inside) / n - AnchoredTriangleArea(a, values[j])));
    }
  }
  return worst;
}

double SphericalTriangleDiscrepancy(const std::vector<Vec3>& points, int triangles, uint64_t seed) {
  const size_t n = points.size();
  if (n == 0) return 0;
  auto random_unit = [&](uint64_t k) {
    const double z = 1 - 2 * CounterUniform(seed, 11, k);
    const double phi = 2 * kPi * CounterUniform(seed, 12, k);
    const double s = std::sqrt(std::max(0.0, 1 - z * z));
    return Vec3{s * std::cos(phi), s * std::sin(phi), z};
  };
  double worst = 0;
  for (int t = 0; t < triangles; ++t) {
    Vec3 a = random_unit(3 * t), b = random_unit(3 * t + 1), c = random_unit(3 * t + 2);
    if (Dot(a, Cross(b, c)) < 0) std::swap(b, c);  // counter-clockwise seen from outside
    const Vec3 nab = Cross(a, b), nbc = Cross(b, c), nca = Cross(c, a);
    const double triple = Dot(a, Cross(b, c));
    const double excess = 2 * std::atan2(triple, 1 + Dot(a, b) + Dot(b, c) + Dot(c, a));
    const double fraction = excess / (4 * kPi);
    size_t inside = 0;
    for (const Vec3& p : points) inside += Dot(p, nab) >= 0 && Dot(p, nbc) >= 0 && Dot(p, nca) >= 0;
    worst = std::max(worst, std::fabs(static_cast<double>(inside) / n - fraction));
  }
  return worst;
}

double ParameterRectDiscrepancy(const std::vector<Point2>& uv,
                                const std::function<double(double, double, double)>& cell_mass,
                                int grid) {
  const size_t n = uv.size();
  if (n == 0) return 0;
  const int g = grid;
  const double h = 1.0 / g;
  // Prefix sums (g+1)^2 of counts and masses: P[i][j] over [0,i/g) x [0,j/g).
  std::vector<double> count((g + 1) * (g + 1), 0), mass((g + 1) * (g + 1), 0);
  auto at = [&](std::vector<double>& m, int i, int j) -> double& { return m[i * (g + 1) + j]; };
  for (const Point2& p : uv) {
    const int i = std::min(g - 1, static_cast<int>(p.x * g));
    const int j = std::min(g - 1, static_cast<int>(p.y * g));
    at(count, i + 1, j + 1) += 1;
  }
  for (int i = 0; i < g; ++i) {
    for (int j = 0; j < g; ++j) at(mass, i + 1, j + 1) = cell_mass(i * h, j * h, h);
  }
  for (int i = 1; i <= g; ++i) {
    for (int j = 1; j <= g; ++j) {
      for (auto* m : {&count, &mass}) {
        at(*m, i, j) += at(*m, i - 1, j) + at(*m, i, j - 1) - at(*m, i - 1, j - 1);
      }
    }
  }
  const double total = at(mass, g, g);
  auto rect = [&](std::vector<double>& m, int i0, int j0, int i1, int j1) {
    return at(m, i1, j1) - at(m, i0, j1) - at(m, i1, j0) + at(m, i0, j0);
  };
  double worst = 0;
  for (int i = 1; i <= g; ++i) {
    for (int j = 1; j <= g; ++j) {
      worst = std::max(worst, std::fabs(at(count, i, j) / n - at(mass, i, j) / total));
    }
  }
  const int step = g >= 8 ? 8 : 1;  // the coarse grid has g/8 cells a side
  for (int i0 = 0; i0 < g; i0 += step) {
    for (int i1 = i0 + step; i1 <= g; i1 += step) {
      for (int j0 = 0; j0 < g; j0 += step) {
        for (int j1 = j0 + step; j1 <= g; j1 += step) {
          worst = std::max(worst, std::fabs(rect(count, i0, j0, i1, j1) / n -
                                            rect(mass, i0, j0, i1, j1) / total));
        }
      }
    }
  }
  return worst;
}

double LogLogSlope(const std::vector<double>& n, const std::vector<double>& d) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  const double m = static_cast<double>(n.size());
  for (size_t i = 0; i < n.size(); ++i) {
    const double x = std::log(n[i]), y = std::log(d[i]);
    sx += x, sy += y, sxx += x * x, sxy += x * y;
  }
  return (m * sxy - sx * sy) / (m * sxx - sx * sx);
}

}  // namespace sfc
