#include "evaluation/protocol.h"

#include <chrono>
#include <cmath>
#include <map>
#include <memory>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "base/counter_hash.h"
#include "base/status_macros.h"
#include "catalog/catalog.h"
#include "core/area_estimator.h"
#include "core/builtin_surfaces.h"
#include "core/sampler.h"
#include "evaluation/discrepancy.h"
#include "evaluation/reference_measure.h"
#include "evaluation/reference_sets.h"

namespace sfc {
namespace {

// Paper Table 1 (rectangular, circular, triangular) and Table 2 (spherical).
const std::map<std::string, std::vector<double>>& PaperPlane() {
  static const auto* const k = new std::map<std::string, std::vector<double>>{
      {"random", {-0.49, -0.50, -0.49}},
      {"sobol", {-0.90, -0.70, -0.58}},
      {"jittered2d", {-0.75, -0.74, -0.72}},
      {"hilbert-jittered", {-0.73, -0.73, -0.72}},
  };
  return *k;
}
const std::map<std::string, double>& PaperSphere() {
  static const auto* const k = new std::map<std::string, double>{
      {"random", -0.49},
      {"hammersley", -0.75},
      {"hilbert-jittered-fff", -0.73},
      {"hilbert-jittered-triangle", -0.71},
  };
  return *k;
}

// Our sampler: trees by grade, each refined from the previous one, as the
// server's cache does; or the sets from `remote` when it is set.
class OurSampler {
 public:
  // `surface_spec` and `density_spec` are the catalogue specs of `surface`
  // and `density`, for `remote`.
  OurSampler(std::shared_ptr<const Surface> surface, CurveTreeOptions options,
             std::shared_ptr<const Density> density, std::string surface_spec,
             std::string density_spec, PointSetSource remote)
      : surface_(std::move(surface)), density_(std::move(density)), options_(options),
        surface_spec_(std::move(surface_spec)), density_spec_(std::move(density_spec)),
        remote_(std::move(remote)) {}

  absl::StatusOr<SampleBatch> Sample(uint64_t n, uint64_t seed) {
    if (remote_) return remote_(surface_spec_, density_spec_, options_, n, seed);
    const int grade = CurveTree::GradeFor(n);
    if (!tree_ || tree_->grade() != grade) {
      if (tree_ && tree_->grade() < grade) {
        ASSIGN_OR_RETURN(tree_, tree_->Refined(*surface_, *density_, grade));
      } else {
        ASSIGN_OR_RETURN(tree_, CurveTree::Build(*surface_, *density_, options_, grade));
      }
    }
    auto sampler = std::make_shared<const Sampler>(tree_, surface_, density_,
                                                   Sequence(SequenceKind::kJittered, n, seed));
    ASSIGN_OR_RETURN(auto cursor, SampleCursor::Create(sampler, 0, n, {}, {}));
    SampleBatch all;
    while (true) {
      ASSIGN_OR_RETURN(const size_t got, cursor->Next(1 << 16, &all));
      if (got == 0) break;
    }
    return all;
  }

 private:
  std::shared_ptr<const Surface> surface_;
  std::shared_ptr<const Density> density_;
  CurveTreeOptions options_;
  std::string surface_spec_, density_spec_;
  PointSetSource remote_;
  std::shared_ptr<const CurveTree> tree_;
};

std::vector<uint64_t> Sizes(int l_min, int l_max) {
  std::vector<uint64_t> sizes;
  for (int l = l_min; l <= l_max; ++l) {
    sizes.push_back(uint64_t{1} << l);
    sizes.push_back((uint64_t{1} << l) + (uint64_t{1} << (l - 1)));
  }
  return sizes;
}

CurveTreeOptions CurveOptions(CurveType curve, AreaEstimator estimator) {
  CurveTreeOptions o;
  o.curve = curve;
  o.estimator = estimator;
  o.max_leaves = uint64_t{1} << 27;
  return o;
}

// Surfaces other than the plane and the sphere, where the density
// discrepancy over parameter rectangles tells whether a density is honoured.
struct SurfaceCase {
  const char* surface;
  const char* density;
  int l_min = 0, l_max = 0;  // own sizes 2^l, 2^l + 2^(l-1); 0: the protocol's
  bool random = true;        // also the i.i.d. baseline (needs a bounded area element)
};
constexpr SurfaceCase kSurfaceCases[] = {
    {"torus", "uniform"},
    {"eight", "gaussian:floor=0.05"},
    {"monkey_saddle", "gaussian:floor=0.01"},
    {"plane", "expr:u+v"},
    // The paper's Sect. 5.3 surface, not reparameterised: the area element is
    // infinite on u = 1/2 and v = 0, 1/4, 1/2, 3/4, 1. N = 64 .. 24576.
    {"superellipsoid", "uniform", 6, 14, false},
};

// i.i.d. points with density proportional to delta dA, by rejection: the
// baseline that should give a slope of -1/2.
absl::StatusOr<std::vector<Point2>> RandomWithDensity(const Surface& surface,
                                                      const Density& density, uint64_t n,
                                                      uint64_t seed) {
  double peak = 0;
  for (int i = 0; i < 64; ++i) {
    for (int j = 0; j < 64; ++j) {
      ASSIGN_OR_RETURN(const DensityAt d,
                       EvaluateDensity(surface, density, (i + 0.5) / 64, (j + 0.5) / 64));
      peak = std::max(peak, d.delta * d.area_element);
    }
  }
  peak *= 1.5;  // margin over the grid's maximum
  std::vector<Point2> pts;
  for (uint64_t k = 0; pts.size() < n; ++k) {
    const double u = CounterUniform(seed, 31, k), v = CounterUniform(seed, 32, k);
    ASSIGN_OR_RETURN(const DensityAt d, EvaluateDensity(surface, density, u, v));
    if (CounterUniform(seed, 33, k) * peak < d.delta * d.area_element) pts.push_back({u, v});
  }
  return pts;
}

}  // namespace

const std::vector<std::string>& PlaneMethods() {
  static const auto* const k = new std::vector<std::string>{
      "random", "jittered2d", "sobol", "halton", "hammersley",
      "hilbert-jittered", "hilbert2-jittered", "peano-jittered"};
  return *k;
}

const std::vector<std::string>& SphereMethods() {
  static const auto* const k = new std::vector<std::string>{
      "random", "hammersley", "fibonacci", "hilbert-jittered-fff", "hilbert-jittered-triangle",
      "hilbert-jittered-quadrature"};
  return *k;
}

absl::StatusOr<std::vector<ProtocolRow>> RunProtocol(
    const ProtocolOptions& options, const std::function<void(int, int)>& progress) {
  if (options.l_min < 1 || options.l_max < options.l_min || options.l_max > 22) {
    return absl::InvalidArgumentError("sizes need 1 <= l_min <= l_max <= 22");
  }
  const auto plane = options.plane_methods.empty() ? PlaneMethods() : options.plane_methods;
  const auto sphere = options.sphere_methods.empty() ? SphereMethods() : options.sphere_methods;
  for (const auto& m : plane) {
    if (std::find(PlaneMethods().begin(), PlaneMethods().end(), m) == PlaneMethods().end()) {
      return absl::InvalidArgumentError(absl::StrCat("unknown plane method ", m));
    }
  }
  for (const auto& m : sphere) {
    if (std::find(SphereMethods().begin(), SphereMethods().end(), m) == SphereMethods().end()) {
      return absl::InvalidArgumentError(absl::StrCat("unknown sphere method ", m));
    }
  }
  const std::vector<uint64_t> sizes = Sizes(options.l_min, options.l_max);
  const int total = static_cast<int>((plane.size() + sphere.size()) * sizes.size());
  // (The surface section reports no progress; it takes a few seconds.)
  int done = 0;
  std::vector<ProtocolRow> rows;
  std::shared_ptr<const Surface> unit_square = MakePlane(), unit_sphere = MakeSphere(1);
  std::shared_ptr<const Density> uniform = MakeUniformDensity();

  for (const std::string& method : plane) {
    std::unique_ptr<OurSampler> ours;
    auto on_square = [&](CurveType curve) {
      return std::make_unique<OurSampler>(unit_square,
                                          CurveOptions(curve, AreaEstimator::kFirstFundamentalForm),
                                          uniform, "plane", "uniform", options.our_sets);
    };
    if (method == "hilbert-jittered") ours = on_square(CurveType::kHilbert);
    if (method == "hilbert2-jittered") ours = on_square(CurveType::kHilbert2);
    if (method == "peano-jittered") ours = on_square(CurveType::kPeano);
    for (uint64_t n : sizes) {
      const auto start = std::chrono::steady_clock::now();
      std::vector<Point2> pts;
      if (ours) {
        ASSIGN_OR_RETURN(const SampleBatch b, ours->Sample(n, options.seed));
        pts.resize(b.size());
        for (size_t i = 0; i < b.size(); ++i) pts[i] = {b.u[i], b.v[i]};
      } else if (method == "random") {
        pts = RandomSquare(n, options.seed);
      } else if (method == "jittered2d") {
        pts = JitteredSquare(n, options.seed);
      } else if (method == "sobol") {
        pts = SobolSquare(n);
      } else if (method == "halton") {
        pts = HaltonSquare(n);
      } else {
        pts = HammersleySquare(n);
      }
      ProtocolRow row;
      row.domain = "plane";
      row.method = method;
      row.n = n;
      row.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      row.rectangular = StarDiscrepancy(pts, options.star_corners);
      row.circular = QuarterDiscDiscrepancy(pts);
      row.triangular = TriangleDiscrepancy(pts, options.triangle_grid);
      rows.push_back(row);
      if (progress) progress(++done, total);
    }
  }
  for (const std::string& method : sphere) {
    std::unique_ptr<OurSampler> ours;
    auto on_sphere = [&](AreaEstimator estimator) {
      return std::make_unique<OurSampler>(unit_sphere, CurveOptions(CurveType::kHilbert, estimator),
                                          uniform, "sphere", "uniform", options.our_sets);
    };
    if (method == "hilbert-jittered-fff") ours = on_sphere(AreaEstimator::kFirstFundamentalForm);
    if (method == "hilbert-jittered-triangle") ours = on_sphere(AreaEstimator::kTriangle);
    if (method == "hilbert-jittered-quadrature") ours = on_sphere(AreaEstimator::kQuadrature);
    for (uint64_t n : sizes) {
      const auto start = std::chrono::steady_clock::now();
      std::vector<Vec3> pts;
      if (ours) {
        ASSIGN_OR_RETURN(const SampleBatch b, ours->Sample(n, options.seed));
        pts.resize(b.size());
        for (size_t i = 0; i < b.size(); ++i) pts[i] = Vec3{b.x[i], b.y[i], b.z[i]};
      } else if (method == "random") {
        pts = RandomSphere(n, options.seed);
      } else if (method == "hammersley") {
        pts = HammersleySphere(n);
      } else {
        pts = FibonacciSphere(n);
      }
      ProtocolRow row;
      row.domain = "sphere";
      row.method = method;
      row.n = n;
      row.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      row.spherical = SphericalTriangleDiscrepancy(pts, options.sphere_triangles, options.seed);
      rows.push_back(row);
      if (progress) progress(++done, total);
    }
  }
  if (options.surfaces) {
    for (const SurfaceCase& c : kSurfaceCases) {
      ASSIGN_OR_RETURN(const SurfaceFromSpec surface, MakeSurface(c.surface));
      ASSIGN_OR_RETURN(const DensityFromSpec density, MakeDensity(c.density));
      const std::string domain =
          absl::StrCat("surface ", c.surface, " with ", c.density,
                       c.l_min ? absl::StrFormat(" (N = %d..%d)", (1 << c.l_min),
                                                 (1 << c.l_max) + (1 << (c.l_max - 1)))
                               : std::string());
      // Cell integrals of delta dA by a graded 8 x 8 Gauss-Legendre rule on a
      // 256 x 256 grid (evaluation/reference_measure.h), computed once per
      // surface; nothing here is shared with the tree.
      constexpr int kGrid = 256;
      ASSIGN_OR_RETURN(const std::vector<double> cells,
                       GradedCellMasses(*surface.surface, *density.density, kGrid, 8));
      auto cell_mass = [&](double u0, double v0, double) {
        return cells[std::lround(u0 * kGrid) * kGrid + std::lround(v0 * kGrid)];
      };
      OurSampler ours(surface.surface,
                      CurveOptions(CurveType::kHilbert, AreaEstimator::kFirstFundamentalForm),
                      density.density, c.surface, c.density, options.our_sets);
      const std::vector<uint64_t> case_sizes = c.l_min ? Sizes(c.l_min, c.l_max) : sizes;
      for (const char* method : {"random", "hilbert-jittered"}) {
        if (!c.random && std::string(method) == "random") continue;
        for (uint64_t n : case_sizes) {
          const auto start = std::chrono::steady_clock::now();
          std::vector<Point2> pts;
          if (std::string(method) == "random") {
            ASSIGN_OR_RETURN(
                pts, RandomWithDensity(*surface.surface, *density.density, n, options.seed));
          } else {
            ASSIGN_OR_RETURN(const SampleBatch b, ours.Sample(n, options.seed));
            for (size_t i = 0; i < b.size(); ++i) pts.push_back({b.u[i], b.v[i]});
          }
          ProtocolRow row;
          row.domain = domain;
          row.method = method;
          row.n = n;
          row.seconds =
              std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
          row.density = ParameterRectDiscrepancy(pts, cell_mass, kGrid);
          rows.push_back(row);
        }
      }
    }
  }
  return rows;
}

std::vector<SlopeRow> Slopes(const std::vector<ProtocolRow>& rows) {
  struct Fit {
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    int n = 0;
    void Add(double x, double y) { sx += x, sy += y, sxx += x * x, sxy += x * y, ++n; }
    double Slope() const { return (n * sxy - sx * sy) / (n * sxx - sx * sx); }
  };
  std::map<std::tuple<std::string, std::string, std::string>, Fit> fits;
  std::vector<std::tuple<std::string, std::string, std::string>> order;
  auto add = [&](const ProtocolRow& r, const char* measure, const std::optional<double>& d) {
    if (!d || !(*d > 0)) return;
    const auto key = std::make_tuple(r.domain, r.method, std::string(measure));
    if (!fits.count(key)) order.push_back(key);
    fits[key].Add(std::log(static_cast<double>(r.n)), std::log(*d));
  };
  for (const ProtocolRow& r : rows) {
    add(r, "rectangular", r.rectangular);
    add(r, "circular", r.circular);
    add(r, "triangular", r.triangular);
    add(r, "spherical", r.spherical);
    add(r, "density", r.density);
  }
  std::vector<SlopeRow> out;
  for (const auto& key : order) {
    SlopeRow s;
    std::tie(s.domain, s.method, s.measure) = key;
    s.slope = fits[key].Slope();
    if (s.domain == "plane" && PaperPlane().count(s.method)) {
      const int i = s.measure == "rectangular" ? 0 : s.measure == "circular" ? 1 : 2;
      s.paper = PaperPlane().at(s.method)[i];
    }
    if (s.domain == "sphere" && PaperSphere().count(s.method)) s.paper = PaperSphere().at(s.method);
    out.push_back(s);
  }
  return out;
}

std::string RowsCsv(const std::vector<ProtocolRow>& rows) {
  std::string out = "domain,method,n,rectangular,circular,triangular,spherical,density,seconds\n";
  auto cell = [](const std::optional<double>& d) {
    return d ? absl::StrFormat("%.6g", *d) : std::string();
  };
  for (const ProtocolRow& r : rows) {
    absl::StrAppend(&out, r.domain, ",", r.method, ",", r.n, ",", cell(r.rectangular), ",",
                    cell(r.circular), ",", cell(r.triangular), ",", cell(r.spherical), ",",
                    cell(r.density), ",",
                    absl::StrFormat("%.4f", r.seconds), "\n");
  }
  return out;
}

std::string SlopeTables(const std::vector<SlopeRow>& slopes) {
  auto find = [&](const std::string& domain, const std::string& method,
                  const std::string& measure) -> const SlopeRow* {
    for (const SlopeRow& s : slopes) {
      if (s.domain == domain && s.method == method && s.measure == measure) return &s;
    }
    return nullptr;
  };
  auto cell = [](const SlopeRow* s) {
    if (!s) return std::string("");
    return s->paper ? absl::StrFormat("%.2f (paper %.2f)", s->slope, *s->paper)
                    : absl::StrFormat("%.2f", s->slope);
  };
  std::string out = "Plane, slope of log D against log N (ours, paper Table 1):\n\n"
                    "| method | rectangular | circular | triangular |\n|---|---:|---:|---:|\n";
  std::vector<std::string> seen;
  for (const SlopeRow& s : slopes) {
    if (s.domain != "plane" || std::find(seen.begin(), seen.end(), s.method) != seen.end())
      continue;
    seen.push_back(s.method);
    absl::StrAppend(&out, "| ", s.method, " | ", cell(find("plane", s.method, "rectangular")),
                    " | ", cell(find("plane", s.method, "circular")), " | ",
                    cell(find("plane", s.method, "triangular")), " |\n");
  }
  absl::StrAppend(&out,
                  "\nSphere, spherical triangles (ours, paper Table 2):\n\n| method | spherical "
                  "|\n|---|---:|\n");
  for (const SlopeRow& s : slopes) {
    if (s.domain == "sphere") absl::StrAppend(&out, "| ", s.method, " | ", cell(&s), " |\n");
  }
  absl::StrAppend(
      &out,
      "\nOther surfaces, density discrepancy over parameter rectangles (not in the paper):\n\n"
      "| surface and density | random (i.i.d. by the density) | hilbert-jittered "
      "|\n|---|---:|---:|\n");
  std::vector<std::string> domains;
  for (const SlopeRow& s : slopes) {
    if (s.measure == "density" &&
        std::find(domains.begin(), domains.end(), s.domain) == domains.end()) {
      domains.push_back(s.domain);
    }
  }
  for (const std::string& d : domains) {
    absl::StrAppend(&out, "| ", d.substr(8), " | ", cell(find(d, "random", "density")), " | ",
                    cell(find(d, "hilbert-jittered", "density")), " |\n");
  }
  return out;
}

}  // namespace sfc
