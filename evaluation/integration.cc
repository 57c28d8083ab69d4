#include "evaluation/integration.h"

#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <map>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "base/status_macros.h"
#include "evaluation/discrepancy.h"
#include "evaluation/gauss_legendre.h"

namespace sfc {
namespace {

constexpr double kPi = 3.14159265358979323846;

double F(double x, double y, double z) { return x * x + 0.3 * y * z + std::exp(z); }
double G(double x, double y, double z) { return x * x + 0.3 * y * z + z; }

struct Vertex {
  double x, y, z;
};

// The icosphere of bench/compare_samplers.py: the icosahedron, each triangle
// split in four `subdivisions` times, new vertices pushed to the unit sphere.
void Icosphere(int subdivisions, std::vector<Vertex>* v, std::vector<std::array<int, 3>>* f) {
  const double t = (1 + std::sqrt(5.0)) / 2;
  const double raw[12][3] = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0},
                             {0, -1, t}, {0, 1, t}, {0, -1, -t}, {0, 1, -t},
                             {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  auto unit = [](double x, double y, double z) {
    const double n = std::sqrt(x * x + y * y + z * z);
    return Vertex{x / n, y / n, z / n};
  };
  v->clear();
  for (const auto& p : raw) v->push_back(unit(p[0], p[1], p[2]));
  *f = {{0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
        {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
        {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (int s = 0; s < subdivisions; ++s) {
    std::map<std::pair<int, int>, int> cache;
    auto mid = [&](int a, int b) {
      const auto key = std::make_pair(std::min(a, b), std::max(a, b));
      auto it = cache.find(key);
      if (it != cache.end()) return it->second;
      const Vertex &p = (*v)[a], &q = (*v)[b];
      v->push_back(unit(p.x + q.x, p.y + q.y, p.z + q.z));
      return cache[key] = static_cast<int>(v->size()) - 1;
    };
    std::vector<std::array<int, 3>> out;
    for (const auto& [a, b, c] : *f) {
      const int ab = mid(a, b), bc = mid(b, c), ca = mid(c, a);
      out.push_back({a, ab, ca}), out.push_back({b, bc, ab});
      out.push_back({c, ca, bc}), out.push_back({ab, bc, ca});
    }
    *f = std::move(out);
  }
}

// Fits log y = c + s log n; the n where the line reaches `target`.
double Reach(const std::vector<double>& n, const std::vector<double>& y, double target) {
  const double s = LogLogSlope(n, y);
  double mx = 0, my = 0;
  for (size_t i = 0; i < n.size(); ++i) mx += std::log(n[i]), my += std::log(y[i]);
  mx /= n.size(), my /= n.size();
  return std::exp(mx + (std::log(target) - my) / s);
}

}  // namespace

double SphereMeanOfF() {
  const double e = std::exp(1.0);
  return (4 * kPi / 3 + 2 * kPi * (e - 1 / e)) / (4 * kPi);
}

double TorusMeanOfF(double big_r, double small_r) {
  constexpr int kNodes = 512;
  double sum = 0, area = 0;
  for (int i = 0; i < kNodes; ++i) {
    const double a = 2 * kPi * i / kNodes;
    for (int j = 0; j < kNodes; ++j) {
      const double b = 2 * kPi * j / kNodes;
      const double w = big_r + small_r * std::cos(b);
      const double d = small_r * w;
      sum += F(w * std::cos(a), w * std::sin(a), small_r * std::sin(b)) * d;
      area += d;
    }
  }
  return sum / area;
}

double SuperellipsoidMeanOfF(double e) {
  // Nodes of each quarter of an angle: quarter start + pi/2 s(t), s = t^3 /
  // (t^3 + (1 - t)^3), whose cosines and sines are formed from the nearer end.
  const GaussRule& rule = GaussLegendreRule(128);
  struct Node {
    double c, s, weight;  // cosine, sine, weight x d angle / dt
  };
  auto quarters = [&](int first, int count) {
    static const int kC[4] = {1, 0, -1, 0}, kS[4] = {0, 1, 0, -1};
    std::vector<Node> nodes;
    for (int k = 0; k < count; ++k) {
      const int q = ((first + k) % 4 + 4) % 4;
      for (size_t i = 0; i < rule.x.size(); ++i) {
        const double t = rule.x[i], u = 1 - t;
        const double den = t * t * t + u * u * u;
        const double s = t * t * t / den, rest = u * u * u / den;
        const double ds = 3 * t * t * u * u / (den * den);
        const double cd = s < 0.5 ? std::cos(kPi / 2 * s) : std::sin(kPi / 2 * rest);
        const double sd = s < 0.5 ? std::sin(kPi / 2 * s) : std::cos(kPi / 2 * rest);
        nodes.push_back(
            {kC[q] * cd - kS[q] * sd, kS[q] * cd + kC[q] * sd, rule.w[i] * kPi / 2 * ds});
      }
    }
    return nodes;
  };
  const std::vector<Node> as = quarters(-1, 2), bs = quarters(-2, 4);
  auto spow = [e](double c) { return std::copysign(std::pow(std::fabs(c), e), c); };
  auto dspow = [e](double c, double dc) { return e * std::pow(std::fabs(c), e - 1) * dc; };
  double sum = 0, area = 0;
  for (const Node& a : as) {
    const double g = spow(a.c), f = spow(a.s);
    const double ga = dspow(a.c, -a.s), fa = dspow(a.s, a.c);
    for (const Node& b : bs) {
      const double h = spow(b.c), s = spow(b.s);
      const double hb = dspow(b.c, -b.s), sb = dspow(b.s, b.c);
      // x = g h, y = g s, z = f: the cross product of the two tangents.
      const double xa = ga * h, ya = ga * s, za = fa, xb = g * hb, yb = g * sb;
      const double nx = -za * yb, ny = za * xb, nz = xa * yb - ya * xb;
      const double d = std::sqrt(nx * nx + ny * ny + nz * nz) * a.weight * b.weight;
      sum += F(g * h, g * s, f) * d;
      area += d;
    }
  }
  return sum / area;
}

absl::StatusOr<std::string> IntegrationTables(const IntegrationOptions& o,
                                              const QualitySource& source,
                                              std::vector<QualityCheck>* checks) {
  struct Case {
    std::string name, spec;
    std::function<double(double, double, double)> func;
    double exact;
    // The check, sobol's error at most a fifth of jittered's at the
    // largest N, is for surfaces without a closed-form area-preserving map.
    bool judged = true;
  };
  std::vector<Case> cases = {
      {"sphere, f", "sphere", F, SphereMeanOfF(), false},
      {"torus R = 2, r = 1, f", "torus:R=2;r=1", F, TorusMeanOfF(2, 1), false},
      {"superellipsoid e = 1/3, f", "superellipsoid", F, SuperellipsoidMeanOfF(1.0 / 3)},
  };
  if (!o.step_sphere.empty())
    cases.push_back({"STEP sphere, f", o.step_sphere, F, SphereMeanOfF()});
  // The icosphere, written as OBJ, and g's exact mean over its flat triangles.
  std::vector<Vertex> v;
  std::vector<std::array<int, 3>> tri;
  Icosphere(4, &v, &tri);
  std::error_code ec;
  std::filesystem::create_directories(o.work_dir, ec);
  const std::string obj = o.work_dir + "/integration_icosphere.obj";
  {
    std::FILE* out = std::fopen(obj.c_str(), "w");
    if (!out) return absl::InternalError(absl::StrCat("cannot write ", obj));
    for (const Vertex& p : v) std::fprintf(out, "v %.17g %.17g %.17g\n", p.x, p.y, p.z);
    for (const auto& [a, b, c] : tri) std::fprintf(out, "f %d %d %d\n", a + 1, b + 1, c + 1);
    if (std::fclose(out) != 0) return absl::InternalError(absl::StrCat("cannot write ", obj));
  }
  double mesh_area = 0, mesh_integral = 0;
  for (const auto& [a, b, c] : tri) {
    const Vertex &p = v[a], &q = v[b], &r = v[c];
    const double ux = q.x - p.x, uy = q.y - p.y, uz = q.z - p.z;
    const double wx = r.x - p.x, wy = r.y - p.y, wz = r.z - p.z;
    const double cx = uy * wz - uz * wy, cy = uz * wx - ux * wz, cz = ux * wy - uy * wx;
    const double area = std::sqrt(cx * cx + cy * cy + cz * cz) / 2;
    auto g = [](const Vertex& s, const Vertex& t) {
      return G((s.x + t.x) / 2, (s.y + t.y) / 2, (s.z + t.z) / 2);
    };
    mesh_area += area;
    mesh_integral += area / 3 * (g(p, q) + g(q, r) + g(r, p));
  }
  cases.push_back(
      {"icosphere mesh (5120 triangles), g", "obj:" + obj, G, mesh_integral / mesh_area});

  std::vector<double> sizes;
  for (int l = 10; l <= (o.full ? 16 : 14); l += 2) sizes.push_back(std::ldexp(1.0, l));
  const SequenceKind modes[] = {SequenceKind::kJittered, SequenceKind::kSobol,
                                SequenceKind::kProgressive};
  std::string out = absl::StrFormat(
      "## Integration: sample means against exact values (issue 36)\n\n"
      "f = x^2 + 0.3 y z + exp(z); g = x^2 + 0.3 y z + z on the mesh. Exact means computed from "
      "the surfaces' formulas (evaluation/integration.h). Mean |error| over seeds %s at each N, "
      "+- its standard error over the seeds; "
      "slope of log error on log N; points and time (the mean run's wall time "
      "fitted as a + b N) to reach 1e-4 and 1e-5 on the fitted line, ~ where it is "
      "extrapolated past N = %d.\n\n",
      absl::StrJoin(o.seeds, ","), static_cast<uint64_t>(sizes.back()));
  for (const Case& c : cases) {
    absl::StrAppend(&out,
                    absl::StrFormat("### %s (exact mean %.15g)\n\n| mode |", c.name, c.exact));
    for (double n : sizes) absl::StrAppend(&out, absl::StrFormat(" N = %d |", uint64_t(n)));
    absl::StrAppend(&out, " slope | to 1e-4 | to 1e-5 |\n|---|");
    for (size_t i = 0; i < sizes.size() + 3; ++i) absl::StrAppend(&out, "---:|");
    absl::StrAppend(&out, "\n");
    std::map<SequenceKind, double> last;
    for (SequenceKind mode : modes) {
      std::vector<double> errors, standard_errors, seconds;
      for (double n : sizes) {
        std::vector<double> seed_errors;  // |error| of each seed's sample mean
        double time = 0;
        for (uint64_t seed : o.seeds) {
          const auto start = std::chrono::steady_clock::now();
          ASSIGN_OR_RETURN(const SampleBatch b, source(c.spec, "uniform", uint64_t(n), seed, mode));
          time += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
          if (b.size() != uint64_t(n)) {
            return absl::InternalError(
                absl::StrFormat("%s: asked for %d, got %d", c.spec, uint64_t(n), b.size()));
          }
          // The STEP sphere's points scaled to the unit sphere.
          double scale = 1;
          if (c.spec == o.step_sphere && b.size() > 0) {
            scale = std::sqrt(b.x[0] * b.x[0] + b.y[0] * b.y[0] + b.z[0] * b.z[0]);
          }
          double mean = 0;
          for (size_t i = 0; i < b.size(); ++i) {
            mean += c.func(b.x[i] / scale, b.y[i] / scale, b.z[i] / scale);
          }
          seed_errors.push_back(std::fabs(mean / b.size() - c.exact));
        }
        double mean_error, standard_error;
        MeanAndStandardError(seed_errors, &mean_error, &standard_error);
        errors.push_back(std::max(mean_error, 1e-300));
        standard_errors.push_back(standard_error);
        seconds.push_back(time / o.seeds.size());
      }
      last[mode] = errors.back();
      std::string row = absl::StrCat("| ", std::string(SequenceName(mode)), " |");
      for (size_t i = 0; i < errors.size(); ++i) {
        absl::StrAppend(&row, absl::StrFormat(" %.2e +- %.1e |", errors[i], standard_errors[i]));
      }
      absl::StrAppend(&row, absl::StrFormat(" %.2f |", LogLogSlope(sizes, errors)));
      for (double target : {1e-4, 1e-5}) {
        const double n = Reach(sizes, errors, target);
        // Time as a + b N, least squares through the measured runs.
        double mn = 0, mt = 0, snn = 0, snt = 0;
        for (size_t i = 0; i < sizes.size(); ++i) mn += sizes[i], mt += seconds[i];
        mn /= sizes.size(), mt /= sizes.size();
        for (size_t i = 0; i < sizes.size(); ++i) {
          snn += (sizes[i] - mn) * (sizes[i] - mn), snt += (sizes[i] - mn) * (seconds[i] - mt);
        }
        const double t = std::max(0.0, mt + std::max(0.0, snt / snn) * (n - mn));
        absl::StrAppend(&row,
                        absl::StrFormat(" %s%.2g (%.2g s) |", n > sizes.back() ? "~" : "", n, t));
      }
      absl::StrAppend(&out, row, "\n");
      if (o.progress)
        o.progress(absl::StrCat("integration ", c.name, ", ", std::string(SequenceName(mode))));
    }
    absl::StrAppend(&out, "\n");
    const double ratio = last[SequenceKind::kJittered] / last[SequenceKind::kSobol];
    checks->push_back({absl::StrFormat("integration, %s, N = %d: jittered / sobol", c.name,
                                       uint64_t(sizes.back())),
                       absl::StrFormat("%.1fx", ratio), c.judged ? ">= 5x" : "",
                       !(o.full && c.judged) ? "INFO"
                       : ratio >= 5          ? "PASS"
                                             : "FAIL"});
  }
  std::filesystem::remove(obj, ec);
  return out;
}

}  // namespace sfc
