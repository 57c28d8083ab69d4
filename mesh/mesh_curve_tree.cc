#include "mesh/mesh_curve_tree.h"

#include <algorithm>
#include <cmath>
#include <type_traits>

#include "absl/strings/str_format.h"
#include "base/status_macros.h"
#include "base/worker_pool.h"
#include "core/curve_tree.h"
#include "mesh/triangle_order.h"

namespace sfc {
namespace {

using Bary = std::array<double, 3>;

Bary Mid(const Bary& a, const Bary& b) {
  return {(a[0] + b[0]) * 0.5, (a[1] + b[1]) * 0.5, (a[2] + b[2]) * 0.5};
}

// Builds the leaves of one triangle (depth-first, curve order).
class TriangleBuilder {
 public:
  TriangleBuilder(const MeshSurface& surface, const MeshDensity& density, double tolerance,
                  double total, double samples, int max_depth)
      : surface_(surface),
        density_(density),
        tolerance_(tolerance),
        total_(total),
        samples_(samples),
        max_depth_(max_depth) {}

  struct Leaf {
    uint64_t path;
    int depth;
    std::array<double, 3> density;
    double mass;
    bool capped;
  };

  absl::StatusOr<double> Evaluate(uint32_t t, const Bary& b) {
    ++evaluations_;
    const double d = density_.Evaluate(surface_.Attributes(t, b));
    if (!std::isfinite(d) || d < 0) {
      const Vec3 p = surface_.Point(t, b);
      return absl::InvalidArgumentError(absl::StrFormat(
          "the density '%s' is %g at (%g, %g, %g) on triangle %d of mesh '%s'; it must be "
          "finite and >= 0 everywhere on the mesh",
          density_.spec(), d, p.x, p.y, p.z, t, surface_.mesh().name));
    }
    return d;
  }

  // The cell's quadratic-exact mass (three edge midpoints) and its linear
  // model's mass, for a cell of area `area`.
  absl::Status Masses(uint32_t t, const std::array<Bary, 3>& c, const std::array<double, 3>& f,
                      double area, double* quadratic, double* linear) {
    double sum = 0;
    for (int i = 0; i < 3; ++i) {
      ASSIGN_OR_RETURN(const double d, Evaluate(t, Mid(c[i], c[(i + 1) % 3])));
      sum += d;
    }
    *quadratic = area * sum / 3;
    *linear = area * (f[0] + f[1] + f[2]) / 3;
    return absl::OkStatus();
  }

  absl::Status Build(uint32_t t, const std::array<Bary, 3>& c, const std::array<double, 3>& f,
                     double area, double quadratic, double linear, uint64_t path, int depth,
                     std::vector<Leaf>* out) {
    // The linear model's error inside the cell, in samples of the request.
    const bool wants = std::abs(quadratic - linear) / total_ * samples_ > tolerance_;
    if (!wants || depth >= max_depth_) {
      out->push_back({path, depth, f, quadratic, wants});
      return absl::OkStatus();
    }
    // Newest-vertex bisection: (E, X, A) -> (E, A, M), (A, X, M).
    const Bary m = Mid(c[0], c[1]);
    ASSIGN_OR_RETURN(const double fm, Evaluate(t, m));
    const std::array<Bary, 3> c0 = {c[0], c[2], m}, c1 = {c[2], c[1], m};
    const std::array<double, 3> f0 = {f[0], f[2], fm}, f1 = {f[2], f[1], fm};
    double q0, l0, q1, l1;
    RETURN_IF_ERROR(Masses(t, c0, f0, area / 2, &q0, &l0));
    RETURN_IF_ERROR(Masses(t, c1, f1, area / 2, &q1, &l1));
    RETURN_IF_ERROR(Build(t, c0, f0, area / 2, q0, l0, path << 1, depth + 1, out));
    return Build(t, c1, f1, area / 2, q1, l1, (path << 1) | 1, depth + 1, out);
  }

  uint64_t evaluations() const { return evaluations_; }

 private:
  const MeshSurface& surface_;
  const MeshDensity& density_;
  const double tolerance_, total_, samples_;
  const int max_depth_;
  uint64_t evaluations_ = 0;
};

// The bounding box hierarchy's leaves hold this many consecutive ranks: 1/8
// of the memory and build time of one leaf per triangle, for a per-triangle
// test inside the leaves a query does not settle.
constexpr size_t kRanksPerBox = 8;
// Meshes with fewer triangles place their ranks on one thread.
constexpr size_t kParallelRanks = 16384;

// A density whose mass over the mesh, as the tree measured it, is zero:
// INVALID_ARGUMENT, as a formula surface's (core/curve_tree.cc).
absl::Status ZeroDensity(const MeshDensity& density, const std::string& mesh) {
  return absl::InvalidArgumentError(absl::StrFormat(
      "the density '%s' gave no mass over mesh '%s' where the tree measured it (zero everywhere, "
      "or positive only in features narrower than the triangles): there is nothing to sample "
      "(check the density, or add a floor)",
      density.spec(), mesh));
}

std::array<Bary, 3> RootCorners(uint8_t roles) {
  const int entry = roles / 3, exit = roles % 3, apex = 3 - entry - exit;
  std::array<Bary, 3> c{};
  c[0][entry] = 1, c[1][exit] = 1, c[2][apex] = 1;
  return c;
}

}  // namespace

absl::StatusOr<std::shared_ptr<const MeshCurveTree>> MeshCurveTree::Build(
    std::shared_ptr<const MeshSurface> surface, std::shared_ptr<const MeshDensity> density,
    const MeshTreeOptions& options) {
  if (options.count < 1 || !(options.tolerance > 0) || options.max_depth < 0 ||
      options.max_depth > 56 || options.threads < 1) {
    return absl::InvalidArgumentError(
        "mesh tree options: count must be >= 1, tolerance > 0, max_depth in [0, 56], threads "
        ">= 1");
  }
  const TriangleMesh& mesh = surface->mesh();
  if (density->needs_weights() && mesh.weights.empty()) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "density '%s' needs per-vertex weights but mesh '%s' has none; name the PLY vertex "
        "property that holds them",
        density->spec(), mesh.name));
  }
  if (density->needs_curvature() && !surface->has_curvature()) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "density '%s' needs curvature: create the MeshSurface with_curvature", density->spec()));
  }
  auto tree = std::shared_ptr<MeshCurveTree>(new MeshCurveTree());
  tree->surface_ = surface;
  tree->density_ = density;
  Stats& stats = tree->stats_;
  stats.grade = 0;
  while (stats.grade < 63 && (uint64_t{1} << stats.grade) < options.count) ++stats.grade;

  // Triangles in curve order: recursive bisection by area (mesh/triangle_order.h).
  std::vector<uint32_t> live;
  std::vector<Vec3> centroid(mesh.triangles.size());
  std::vector<double> area(mesh.triangles.size());
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    if (surface->degenerate(t)) continue;
    live.push_back(static_cast<uint32_t>(t));
    const auto& f = mesh.triangles[t];
    centroid[t] = (mesh.positions[f[0]] + mesh.positions[f[1]] + mesh.positions[f[2]]) * (1.0 / 3);
    area[t] = surface->area(t);
  }
  const std::vector<uint32_t> order = CurveOrderOfTriangles(live, centroid, area, options.threads);
  const size_t ranks = order.size();
  tree->rank_triangle_ = order;
  tree->rank_roles_.resize(ranks);
  tree->box_leaves_ = 1;
  while (tree->box_leaves_ * kRanksPerBox < ranks) tree->box_leaves_ *= 2;
  // Each rank's roles, in runs of whole box leaves, on the worker pool (the
  // boxes later, in the same parts).
  const size_t parts =
      ranks >= kParallelRanks ? static_cast<size_t>(std::min(options.threads, 8)) : 1;
  tree->box_parts_ = parts;
  const size_t leaves_per_part = (ranks + kRanksPerBox - 1) / kRanksPerBox / parts + 1;
  WorkerPool::Shared().ParallelFor(static_cast<int>(parts), [&](int part) {
    const size_t a = std::min(ranks, part * leaves_per_part * kRanksPerBox);
    const size_t b = std::min(ranks, (part + 1) * leaves_per_part * kRanksPerBox);
    tree->PlaceRanks(a, b, centroid);
  });

  // Masses.
  tree->rank_first_leaf_.resize(ranks + 1);
  stats.triangles = ranks;
  double running = 0;
  if (density->uniform()) {
    tree->leaf_rank_.resize(ranks);
    tree->leaf_path_.assign(ranks, 0);
    tree->leaf_depth_.assign(ranks, 0);
    tree->mass_ends_.resize(ranks);
    for (size_t r = 0; r < ranks; ++r) {
      tree->rank_first_leaf_[r] = static_cast<uint32_t>(r);
      tree->leaf_rank_[r] = static_cast<uint32_t>(r);
      running += area[tree->rank_triangle_[r]];  // 0.5 |e1 x e2|, computed above
      tree->mass_ends_[r] = running;
    }
    tree->rank_first_leaf_[ranks] = static_cast<uint32_t>(ranks);
    RETURN_IF_ERROR(CurveTree::CheckMassIsFinite(running, absl::StrFormat("mesh '%s'", mesh.name)));
  } else {
    // Densities at the mesh vertices, shared by the triangles' roots.
    std::vector<double> vertex_density(mesh.positions.size(), -1);
    TriangleBuilder probe(*surface, *density, 0, 1, 0, 0);
    std::vector<std::array<double, 3>> root_f(ranks);
    std::vector<double> root_q(ranks), root_l(ranks);
    double total0 = 0;
    for (size_t r = 0; r < ranks; ++r) {
      const uint32_t t = tree->rank_triangle_[r];
      const auto c = RootCorners(tree->rank_roles_[r]);
      const int entry = tree->rank_roles_[r] / 3, exit = tree->rank_roles_[r] % 3;
      const int roles[3] = {entry, exit, 3 - entry - exit};
      for (int i = 0; i < 3; ++i) {
        double& vd = vertex_density[mesh.triangles[t][roles[i]]];
        if (vd < 0) {
          ASSIGN_OR_RETURN(vd, probe.Evaluate(t, c[i]));
        }
        root_f[r][i] = vd;
      }
      const double area = surface->area(t);
      RETURN_IF_ERROR(probe.Masses(t, c, root_f[r], area, &root_q[r], &root_l[r]));
      total0 += root_q[r];
    }
    RETURN_IF_ERROR(CurveTree::CheckMassIsFinite(total0, absl::StrFormat("mesh '%s'", mesh.name)));
    if (!(total0 > 0)) {
      return ZeroDensity(*density, mesh.name);
    }
    if (total0 < CurveTree::kSmallestMass) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "the density '%s' integrates to %g over mesh '%s', too small to resolve (below %g); "
          "scale it up: only its ratios matter",
          density->spec(), total0, mesh.name, CurveTree::kSmallestMass));
    }
    TriangleBuilder builder(*surface, *density, options.tolerance, total0,
                            std::ldexp(1.0, stats.grade), options.max_depth);
    std::vector<TriangleBuilder::Leaf> leaves;
    for (size_t r = 0; r < ranks; ++r) {
      const uint32_t t = tree->rank_triangle_[r];
      tree->rank_first_leaf_[r] = static_cast<uint32_t>(tree->mass_ends_.size());
      leaves.clear();
      RETURN_IF_ERROR(builder.Build(t, RootCorners(tree->rank_roles_[r]), root_f[r],
                                    surface->area(t), root_q[r], root_l[r], 0, 0, &leaves));
      if (tree->mass_ends_.size() + leaves.size() > options.max_leaves ||
          tree->mass_ends_.size() + leaves.size() > UINT32_MAX) {
        return absl::ResourceExhaustedError(absl::StrFormat(
            "the curve tree of mesh '%s' for density '%s' needs more than %d leaves "
            "(max_leaves); ask for fewer samples or raise the tolerance",
            mesh.name, density->spec(), options.max_leaves));
      }
      if (leaves.size() > 1) ++stats.split_triangles;
      for (const auto& leaf : leaves) {
        tree->leaf_rank_.push_back(static_cast<uint32_t>(r));
        tree->leaf_path_.push_back(leaf.path);
        tree->leaf_depth_.push_back(static_cast<uint8_t>(leaf.depth));
        tree->leaf_density_.push_back(leaf.density);
        running += leaf.mass;
        tree->mass_ends_.push_back(running);
        stats.max_depth = std::max(stats.max_depth, leaf.depth);
        if (leaf.capped) ++stats.capped_leaves;
      }
    }
    tree->rank_first_leaf_[ranks] = static_cast<uint32_t>(tree->mass_ends_.size());
    stats.density_evaluations = probe.evaluations() + builder.evaluations();
    if (!(running > 0)) {
      return ZeroDensity(*density, mesh.name);
    }
  }
  stats.leaves = tree->mass_ends_.size();
  stats.bytes = tree->rank_triangle_.size() * 4 + tree->rank_roles_.size() +
                tree->rank_first_leaf_.size() * 4 + tree->leaf_rank_.size() * 4 +
                tree->leaf_path_.size() * 8 + tree->leaf_depth_.size() +
                tree->leaf_density_.size() * 24 + tree->mass_ends_.size() * 8 +
                2 * tree->box_leaves_ * sizeof(Box);  // the boxes, once built
  return std::shared_ptr<const MeshCurveTree>(std::move(tree));
}

MeshCurveTree::Cell MeshCurveTree::LeafCell(size_t l) const {
  Cell cell;
  cell.rank = leaf_rank_[l];
  cell.triangle = rank_triangle_[cell.rank];
  cell.corner = RootCorners(rank_roles_[cell.rank]);
  const int depth = leaf_depth_[l];
  const uint64_t path = leaf_path_[l];
  for (int level = depth - 1; level >= 0; --level) {
    const Bary m = Mid(cell.corner[0], cell.corner[1]);
    if ((path >> level) & 1) {
      cell.corner = {cell.corner[2], cell.corner[1], m};
    } else {
      cell.corner = {cell.corner[0], cell.corner[2], m};
    }
  }
  cell.area_size = std::ldexp(1.0, -depth);
  cell.area_begin = static_cast<double>(path) * cell.area_size;
  if (!leaf_density_.empty()) {
    cell.density = leaf_density_[l];
    cell.uniform = cell.density[0] == cell.density[1] && cell.density[1] == cell.density[2];
  }
  return cell;
}

namespace {

// A cell's frame puts its entry, exit and apex at (0, 0), (1, 0), (0, 1).
// Child 0 = (E, A, M) and child 1 = (A, X, M), M = (E + X) / 2, are the
// affine maps of the child's frame into the parent's:
//   T0(a, b) = (b / 2, a),   T1(a, b) = (a + b / 2, 1 - a - b).
struct Affine {
  double a11, a12, a21, a22, c1, c2;
  void Apply(double* x, double* y) const {
    const double nx = a11 * *x + a12 * *y + c1, ny = a21 * *x + a22 * *y + c2;
    *x = nx, *y = ny;
  }
  Affine Then(const Affine& inner) const {  // this o inner
    return {a11 * inner.a11 + a12 * inner.a21, a11 * inner.a12 + a12 * inner.a22,
            a21 * inner.a11 + a22 * inner.a21, a21 * inner.a12 + a22 * inner.a22,
            a11 * inner.c1 + a12 * inner.c2 + c1, a21 * inner.c1 + a22 * inner.c2 + c2};
  }
};
constexpr Affine kChild[2] = {{0, 0.5, 1, 0, 0, 0}, {1, 0.5, -1, -1, 0, 1}};

// The composition of 8 levels for each byte of child choices (highest bit =
// outermost level). Coefficients are dyadic with small numerators: exact.
const std::array<Affine, 256>& ByteMaps() {
  static const std::array<Affine, 256> maps = [] {
    std::array<Affine, 256> m{};
    for (int v = 0; v < 256; ++v) {
      Affine f{1, 0, 0, 1, 0, 0};
      for (int bit = 7; bit >= 0; --bit) f = f.Then(kChild[(v >> bit) & 1]);
      m[v] = f;
    }
    return m;
  }();
  return maps;
}

// The centroid of the cell reached by `levels` child choices (`bits`, first
// level highest), in the starting cell's frame. Innermost levels first, a
// byte at a time: no branches on the bits.
void InnerPoint(uint64_t bits, int levels, double* x, double* y) {
  const auto& maps = ByteMaps();
  *x = 1.0 / 3, *y = 1.0 / 3;
  for (; levels >= 8; levels -= 8, bits >>= 8) maps[bits & 255].Apply(x, y);
  for (; levels > 0; --levels, bits >>= 1) kChild[bits & 1].Apply(x, y);
}

// The maps of ByteMaps() and kChild as columns of two lanes, so that one
// packed multiply-add step moves both coordinates: lane i computes
// (a_i1 * x + a_i2 * y) + c_i, the scalar Apply's operations in its order,
// so the packed and scalar walks agree to the bit (IEEE lanes; no FMA).
typedef double Lanes __attribute__((vector_size(16)));
struct PackedAffine {
  Lanes first, second, offset;  // {a11, a21}, {a12, a22}, {c1, c2}
  Lanes Apply(Lanes xy) const {
    const Lanes xx = {xy[0], xy[0]}, yy = {xy[1], xy[1]};
    return first * xx + second * yy + offset;
  }
};

PackedAffine Pack(const Affine& f) {
  PackedAffine p;
  p.first = Lanes{f.a11, f.a21};
  p.second = Lanes{f.a12, f.a22};
  p.offset = Lanes{f.c1, f.c2};
  return p;
}

const std::array<PackedAffine, 256>& PackedByteMaps() {
  static const std::array<PackedAffine, 256> maps = [] {
    std::array<PackedAffine, 256> m{};
    for (int v = 0; v < 256; ++v) m[v] = Pack(ByteMaps()[v]);
    return m;
  }();
  return maps;
}

constexpr int kLevels = MeshCurveTree::kLevels;

// The child choices of a uniform cell: the first 52 binary digits of t.
uint64_t UniformBits(double t) { return static_cast<uint64_t>(t * 4503599627370496.0); }  // 2^52

// Maps a point of a uniform cell's frame to barycentrics; the area position.
void FinishUniform(const MeshCurveTree::Cell& cell, uint64_t bits, double ca, double cb,
                   std::array<double, 3>* bary, double* area_position) {
  *area_position = cell.area_begin + cell.area_size * ((static_cast<double>(bits) + 0.5) *
                                                       (1.0 / 4503599627370496.0));
  const Bary &e = cell.corner[0], &x = cell.corner[1], &a = cell.corner[2];
  for (int i = 0; i < 3; ++i) (*bary)[i] = e[i] + ca * (x[i] - e[i]) + cb * (a[i] - e[i]);
}

// The centroids of the sub-cells `bits` (kLevels choices each) of n cells,
// in their frames: InnerPoint(bits[j], kLevels, ...) for each, both
// coordinates in one packed step. kGroup samples at a time walk all their
// levels together in registers, so their chains of dependent steps overlap
// (the same operations in the same order for each sample: the same bits).
void InnerPoints(size_t n, const uint64_t* bits, Lanes* xy) {
  const auto& maps = PackedByteMaps();
  static const PackedAffine child[2] = {Pack(kChild[0]), Pack(kChild[1])};
  constexpr size_t kGroup = 8;
  auto walk = [&](auto group, size_t j0) {
    constexpr size_t g = decltype(group)::value;
    Lanes p[g];
    uint64_t b[g];
    for (size_t k = 0; k < g; ++k) p[k] = Lanes{1.0 / 3, 1.0 / 3}, b[k] = bits[j0 + k];
    for (int byte = 0; byte < kLevels / 8; ++byte) {
      for (size_t k = 0; k < g; ++k) p[k] = maps[(b[k] >> (8 * byte)) & 255].Apply(p[k]);
    }
    for (int level = kLevels / 8 * 8; level < kLevels; ++level) {
      for (size_t k = 0; k < g; ++k) p[k] = child[(b[k] >> level) & 1].Apply(p[k]);
    }
    for (size_t k = 0; k < g; ++k) xy[j0 + k] = p[k];
  };
  size_t j = 0;
  for (; j + kGroup <= n; j += kGroup) walk(std::integral_constant<size_t, kGroup>{}, j);
  for (; j < n; ++j) walk(std::integral_constant<size_t, 1>{}, j);
}

}  // namespace

void MeshCurveTree::DescendMany(size_t n, const Cell* const* cells, const double* t,
                                std::array<double, 3>* bary, double* area_position) {
  constexpr size_t kMax = 64;
  size_t uniform[kMax];
  uint64_t bits[kMax] = {};
  Lanes xy[kMax];
  size_t u = 0;
  for (size_t i = 0; i < n; ++i) {
    if (cells[i]->uniform && u < kMax) {
      uniform[u] = i;
      bits[u] = UniformBits(t[i]);
      ++u;
    } else {
      Descend(*cells[i], t[i], &bary[i], &area_position[i]);
    }
  }
  InnerPoints(u, bits, xy);
  for (size_t j = 0; j < u; ++j) {
    const size_t i = uniform[j];
    FinishUniform(*cells[i], bits[j], xy[j][0], xy[j][1], &bary[i], &area_position[i]);
  }
}

void MeshCurveTree::DescendPaths(size_t n, const Cell* const* cells, const uint64_t* paths,
                                 std::array<double, 3>* bary, double* area_position) {
  constexpr size_t kMax = 64;
  Lanes xy[kMax];
  for (size_t i0 = 0; i0 < n; i0 += kMax) {
    const size_t m = std::min(kMax, n - i0);
    InnerPoints(m, paths + i0, xy);
    for (size_t j = 0; j < m; ++j) {
      FinishUniform(*cells[i0 + j], paths[i0 + j], xy[j][0], xy[j][1], &bary[i0 + j],
                    &area_position[i0 + j]);
    }
  }
}

uint64_t MeshCurveTree::PathOf(double pa, double pb) {
  // Each level maps the point into the frame of the child holding it, by the
  // inverse of that child's map T0 or T1.
  uint64_t path = 0;
  for (int level = 0; level < kLevels; ++level) {
    if (2 * pa + pb < 1) {  // child (E, A, M): frame (a, b) -> (b, 2a)
      const double na = pb, nb = 2 * pa;
      pa = na, pb = nb;
      path <<= 1;
    } else {  // child (A, X, M): (a, b) -> (2a + b - 1, 2 (1 - a - b))
      const double na = 2 * pa + pb - 1, nb = 2 * (1 - pa - pb);
      pa = na, pb = nb;
      path = path << 1 | 1;
    }
    pa = std::clamp(pa, 0.0, 1.0), pb = std::clamp(pb, 0.0, 1.0 - pa);
  }
  return path;
}

void MeshCurveTree::Descend(const Cell& cell, double t, std::array<double, 3>* bary,
                            double* area_position) {
  double ca, cb;  // the final centroid in the leaf's frame
  if (cell.uniform) {
    // Equal children: the child choices are the binary digits of t.
    const uint64_t bits = UniformBits(t);
    InnerPoint(bits, kLevels, &ca, &cb);
    FinishUniform(cell, bits, ca, cb, bary, area_position);
    return;
  } else {
    // Follow the linear model level by level while it still varies across
    // the cell, then the remaining digits of t as for a uniform cell.
    double ea = 0, eb = 0, xa = 1, xb = 0, aa = 0, ab = 1;
    double fe = cell.density[0], fx = cell.density[1], fa = cell.density[2];
    double pos = cell.area_begin, size = cell.area_size;
    int level = 0;
    for (; level < kLevels; ++level) {
      // Once the model varies across the cell by less than 2^(level/2 - 26)
      // of its value, it moves the sample by less than 2^-26 of the cell's
      // size, the final resolution (cells halve in diameter every two
      // levels): the remaining levels are pure curve bits.
      const double lo = std::min({fe, fx, fa}), hi = std::max({fe, fx, fa});
      if (hi - lo <= std::ldexp(hi, level / 2 - 26)) break;
      const double ma = (ea + xa) * 0.5, mb = (eb + xb) * 0.5;
      const double fm = (fe + fx) * 0.5;
      // Exact integrals of the linear model over the two equal-area children.
      const double m0 = fe + fa + fm, m1 = fa + fx + fm;
      const double split = m0 + m1 > 0 ? m0 / (m0 + m1) : 0.5;
      size *= 0.5;
      if (t < split) {
        t = t / split;
        xa = aa, xb = ab, fx = fa;
      } else {
        t = (t - split) / (1 - split);
        ea = aa, eb = ab, fe = fa;
        pos += size;
      }
      aa = ma, ab = mb, fa = fm;
      if (!(t < 1)) t = std::nextafter(1.0, 0.0);
      if (!(t >= 0)) t = 0;
    }
    const int rest = kLevels - level;
    const uint64_t bits = static_cast<uint64_t>(std::ldexp(t, rest));
    double ia, ib;
    InnerPoint(bits, rest, &ia, &ib);
    ca = ea + ia * (xa - ea) + ib * (aa - ea);
    cb = eb + ia * (xb - eb) + ib * (ab - eb);
    *area_position = pos + size * std::ldexp(static_cast<double>(bits) + 0.5, -rest);
  }
  const Bary &e = cell.corner[0], &x = cell.corner[1], &a = cell.corner[2];
  for (int i = 0; i < 3; ++i) (*bary)[i] = e[i] + ca * (x[i] - e[i]) + cb * (a[i] - e[i]);
}

namespace {


void AppendRun(size_t a, size_t e, std::vector<std::pair<size_t, size_t>>* runs) {
  if (!runs->empty() && runs->back().second == a) {
    runs->back().second = e;
  } else {
    runs->emplace_back(a, e);
  }
}

}  // namespace

MeshCurveTree::Box MeshCurveTree::TriangleBox(size_t r) const {
  const TriangleMesh& mesh = surface_->mesh();
  Box b{{HUGE_VAL, HUGE_VAL, HUGE_VAL}, {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL}};
  for (uint32_t v : mesh.triangles[rank_triangle_[r]]) {
    const Vec3& p = mesh.positions[v];
    b.lo = {std::min(b.lo.x, p.x), std::min(b.lo.y, p.y), std::min(b.lo.z, p.z)};
    b.hi = {std::max(b.hi.x, p.x), std::max(b.hi.y, p.y), std::max(b.hi.z, p.z)};
  }
  return b;
}

void MeshCurveTree::PlaceRanks(size_t begin, size_t end, const std::vector<Vec3>& centroid) {
  const TriangleMesh& mesh = surface_->mesh();
  const size_t ranks = rank_triangle_.size();
  // Entry and exit: the ends of the longest edge; the exit is the end nearer
  // the next triangle's centroid (the last triangle: the entry is the end
  // nearer the previous one's).
  for (size_t r = begin; r < end; ++r) {
    const auto& f = mesh.triangles[rank_triangle_[r]];
    int p = 0;
    double longest = -1;
    for (int e = 0; e < 3; ++e) {
      const Vec3 d = mesh.positions[f[(e + 1) % 3]] - mesh.positions[f[e]];
      if (Dot(d, d) > longest) longest = Dot(d, d), p = e;
    }
    const int q = (p + 1) % 3;
    auto dist = [&](int corner, const Vec3& to) {
      const Vec3 d = mesh.positions[f[corner]] - to;
      return Dot(d, d);
    };
    bool p_is_entry;
    if (r + 1 < ranks) {
      const Vec3& next = centroid[rank_triangle_[r + 1]];
      p_is_entry = !(dist(p, next) < dist(q, next));
    } else if (r > 0) {
      const Vec3& prev = centroid[rank_triangle_[r - 1]];
      p_is_entry = !(dist(q, prev) < dist(p, prev));
    } else {
      p_is_entry = true;
    }
    const int entry = p_is_entry ? p : q, exit = p_is_entry ? q : p;
    rank_roles_[r] = static_cast<uint8_t>(entry * 3 + exit);
  }
}

void MeshCurveTree::BuildBoxes() const {
  const Box empty{{HUGE_VAL, HUGE_VAL, HUGE_VAL}, {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL}};
  boxes_.assign(2 * box_leaves_, empty);
  const size_t ranks = rank_triangle_.size();
  const size_t leaves_per_part = (ranks + kRanksPerBox - 1) / kRanksPerBox / box_parts_ + 1;
  WorkerPool::Shared().ParallelFor(static_cast<int>(box_parts_), [&](int part) {
    const size_t a = std::min(ranks, part * leaves_per_part * kRanksPerBox);
    const size_t e = std::min(ranks, (part + 1) * leaves_per_part * kRanksPerBox);
    for (size_t r = a; r < e; ++r) {
      Box& b = boxes_[box_leaves_ + r / kRanksPerBox];
      const Box t = TriangleBox(r);
      b.lo = {std::min(b.lo.x, t.lo.x), std::min(b.lo.y, t.lo.y), std::min(b.lo.z, t.lo.z)};
      b.hi = {std::max(b.hi.x, t.hi.x), std::max(b.hi.y, t.hi.y), std::max(b.hi.z, t.hi.z)};
    }
  });
  for (size_t i = box_leaves_ - 1; i >= 1; --i) {
    const Box &a = boxes_[2 * i], &b = boxes_[2 * i + 1];
    boxes_[i] = {{std::min(a.lo.x, b.lo.x), std::min(a.lo.y, b.lo.y), std::min(a.lo.z, b.lo.z)},
                 {std::max(a.hi.x, b.hi.x), std::max(a.hi.y, b.hi.y), std::max(a.hi.z, b.hi.z)}};
  }
}

void MeshCurveTree::RanksMeetingBox(const Vec3& lo, const Vec3& hi,
                                    std::vector<std::pair<size_t, size_t>>* runs) const {
  std::call_once(boxes_once_, [this] { BuildBoxes(); });
  CollectRuns(1, 0, box_leaves_ * kRanksPerBox, lo, hi, runs);
}

void MeshCurveTree::CollectRuns(size_t node, size_t node_lo, size_t node_hi, const Vec3& lo,
                                const Vec3& hi,
                                std::vector<std::pair<size_t, size_t>>* runs) const {
  auto meets = [&](const Box& b) {
    return !(b.lo.x > hi.x || b.hi.x < lo.x || b.lo.y > hi.y || b.hi.y < lo.y || b.lo.z > hi.z ||
             b.hi.z < lo.z);
  };
  const Box& b = boxes_[node];
  if (!meets(b) || node_lo >= rank_triangle_.size()) return;
  const size_t end = std::min(node_hi, rank_triangle_.size());
  const bool inside = b.lo.x >= lo.x && b.hi.x <= hi.x && b.lo.y >= lo.y && b.hi.y <= hi.y &&
                      b.lo.z >= lo.z && b.hi.z <= hi.z;
  if (inside) {
    AppendRun(node_lo, end, runs);
    return;
  }
  if (node >= box_leaves_) {
    for (size_t r = node_lo; r < end; ++r) {
      if (meets(TriangleBox(r))) AppendRun(r, r + 1, runs);
    }
    return;
  }
  const size_t mid = (node_lo + node_hi) / 2;
  CollectRuns(2 * node, node_lo, mid, lo, hi, runs);
  CollectRuns(2 * node + 1, mid, node_hi, lo, hi, runs);
}

}  // namespace sfc
