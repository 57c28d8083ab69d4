#include "core/curve_tree.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "core/status_macros.h"

namespace sfc {
namespace {

void RecordHit(const DepthCapHit& hit, PrecisionReport* report) {
  auto& worst = report->worst;
  auto ratio = [](const DepthCapHit& h) { return h.limit > 0 ? h.measured / h.limit : INFINITY; };
  if (worst.size() == PrecisionReport::kMaxReported && ratio(hit) <= ratio(worst.back())) return;
  auto pos = std::upper_bound(worst.begin(), worst.end(), hit, [&](const auto& a, const auto& b) {
    return ratio(a) > ratio(b);
  });
  worst.insert(pos, hit);
  if (worst.size() > PrecisionReport::kMaxReported) worst.pop_back();
}

absl::Status LeafBudgetError(uint64_t max_leaves) {
  return absl::ResourceExhaustedError(absl::StrFormat(
      "the curve tree needs more than %d leaves (the max_leaves budget, %d bytes at %d bytes a "
      "leaf); ask for fewer samples, raise the tolerance or rho, lower the depth cap, or raise the "
      "budget",
      max_leaves, max_leaves * CurveTree::kBytesPerLeaf, CurveTree::kBytesPerLeaf));
}

}  // namespace

// Holds what one build or refinement pass needs; not thread-safe, one per call.
class CurveTree::Builder {
 public:
  Builder(const Surface& surface, const Density& density, const CurveTreeOptions& options,
          const BuildControl& control)
      : surface_(surface),
        density_(density),
        options_(options),
        control_(control),
        curve_(Curve::Get(options.curve)),
        // Trees with the triangle estimator decide splits with (c): (a) needs
        // neighbours that do not exist yet while a cell is being split.
        decision_estimator_(options.estimator == AreaEstimator::kTriangle
                                ? AreaEstimator::kFirstFundamentalForm
                                : options.estimator) {}

  // Stage 1: the paper's PopulateCurveTree from the root.
  absl::Status BuildGeometric() {
    return Geometric(0, 0, 0, 0, Curve::kRootState);
  }

  // Per-leaf masses (not running sums) for the leaves in starts_, for the
  // triangle estimator; the others fill masses_ as leaves are made.
  absl::Status ComputeTriangleMasses() {
    const size_t n = starts_.size();
    std::vector<double> cu(n), cv(n);
    for (size_t l = 0; l < n; ++l) {
      const CurveTree::Cell cell = CellOf(l);
      cu[l] = cell.u0 + cell.size / 2;
      cv[l] = cell.v0 + cell.size / 2;
    }
    masses_.resize(n);
    if (n < 3) {
      for (size_t l = 0; l < n; ++l) {
        const CurveTree::Cell cell = CellOf(l);
        ASSIGN_OR_RETURN(masses_[l], CellMass(surface_, density_, AreaEstimator::kFirstFundamentalForm,
                                              cell.u0, cell.v0, cell.size));
      }
      return absl::OkStatus();
    }
    for (size_t l = 0; l < n; ++l) {
      // The end vertices use the nearest full triangle.
      const size_t mid = std::clamp<size_t>(l, 1, n - 2);
      ASSIGN_OR_RETURN(masses_[l], TriangleMass(surface_, density_, cu[mid - 1], cv[mid - 1],
                                                cu[mid], cv[mid], cu[mid + 1], cv[mid + 1]));
    }
    return absl::OkStatus();
  }

  // One refinement pass to `grade` over `prev`, filling starts_ and masses_.
  absl::Status RefinePass(const CurveTree& prev, int grade) {
    StartMassPass(prev, grade);
    const size_t n = prev.leaf_count();
    starts_.clear();
    masses_.clear();
    // Most passes that split grow the tree by less than half.
    starts_.reserve(n + n / 2);
    masses_.reserve(n + n / 2);
    for (size_t l = 0; l < n; ++l) {
      const double s = prev.mass_end(l) - prev.mass_begin(l);
      if (s <= limit_) {
        RETURN_IF_ERROR(Keep(prev.starts_[l], s));
        continue;
      }
      const CurveTree::Cell cell = prev.LeafCell(l);
      if (cell.depth >= options_.depth_cap) {
        RecordMassHit(cell.u0, cell.v0, cell.size, s);
        RETURN_IF_ERROR(Keep(prev.starts_[l], s));
        continue;
      }
      RETURN_IF_ERROR(SplitForMass(cell.depth, prev.starts_[l], cell.x, cell.y, cell.state));
    }
    return absl::OkStatus();
  }

  // For a pass that splits nothing: reports the leaves the cap keeps above
  // this grade's mass limit.
  void ReportMassCaps(const CurveTree& prev, int grade) {
    StartMassPass(prev, grade);
    for (size_t l = 0; l < prev.leaf_count(); ++l) {
      const double s = prev.mass_end(l) - prev.mass_begin(l);
      if (s <= limit_) continue;
      const CurveTree::Cell cell = prev.LeafCell(l);
      RecordMassHit(cell.u0, cell.v0, cell.size, s);
    }
  }

  // True when RefinePass(prev, grade) would split some leaf.
  bool PassSplits(const CurveTree& prev, int grade) const {
    const double limit = options_.rho * prev.base_mass_ / std::ldexp(1.0, grade);
    for (size_t l = 0; l < prev.leaf_count(); ++l) {
      if (prev.mass_end(l) - prev.mass_begin(l) > limit &&
          prev.leaf_depth(l) < options_.depth_cap) {
        return true;
      }
    }
    return false;
  }

  // Installs starts_ and running sums of masses_ into `tree`.
  absl::Status Finish(CurveTree* tree) {
    if (options_.estimator == AreaEstimator::kTriangle) RETURN_IF_ERROR(ComputeTriangleMasses());
    tree->starts_ = std::move(starts_);
    tree->mass_end_.resize(masses_.size());
    double sum = 0;
    for (size_t l = 0; l < masses_.size(); ++l) tree->mass_end_[l] = sum += masses_[l];
    if (!(sum > 0) || !std::isfinite(sum)) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "the density integrates to %g over the surface; it must be positive somewhere (check "
          "the density, or add a floor)",
          sum));
    }
    tree->precision_ = report_;
    tree->ComputeDepthRange();
    return absl::OkStatus();
  }

  void set_report(const PrecisionReport& r) { report_ = r; }
  const PrecisionReport& report() const { return report_; }

 private:
  absl::Status Geometric(int depth, uint64_t start, uint64_t x, uint64_t y, int state) {
    RETURN_IF_ERROR(Checkpoint());
    const double h = 1.0 / curve_.PowG(depth);
    const double u0 = x * h, v0 = y * h;
    NoteDepth(depth, u0 + h / 2, v0 + h / 2);
    ASSIGN_OR_RETURN(const double spread, CellSpread(u0, v0, h));
    const bool wants_split = spread > options_.tolerance;
    if (wants_split && depth < options_.depth_cap) {
      const uint64_t span = curve_.Span(depth + 1);
      const int g = curve_.grid();
      for (int c = 0; c < curve_.arity(); ++c) {
        const Curve::Child& ch = curve_.ChildOf(state, c);
        RETURN_IF_ERROR(Geometric(depth + 1, start + c * span, x * g + ch.dx, y * g + ch.dy, ch.state));
      }
      return absl::OkStatus();
    }
    if (wants_split) {
      ++report_.geometry_capped_leaves;
      RecordHit({DepthCapHit::Test::kGeometry, u0, v0, h, spread, options_.tolerance}, &report_);
    }
    double mass = 0;
    if (options_.estimator != AreaEstimator::kTriangle) {
      ASSIGN_OR_RETURN(mass, CellMass(surface_, density_, options_.estimator, u0, v0, h));
    }
    return Keep(start, mass);
  }

  // AssessSubdivision: the largest distance from f(centre) to f at the 4
  // corners and 4 edge midpoints of the cell.
  absl::StatusOr<double> CellSpread(double u0, double v0, double h) const {
    const Vec3 c = surface_.Point(u0 + h / 2, v0 + h / 2);
    double spread = 0;
    for (int i = 0; i <= 2; ++i) {
      for (int j = 0; j <= 2; ++j) {
        const double u = u0 + i * (h / 2), v = v0 + j * (h / 2);
        const Vec3 p = (i == 1 && j == 1) ? c : surface_.Point(u, v);
        if (!IsFinite(p)) {
          return SurfaceNotFiniteError(u, v);
        }
        spread = std::max(spread, Norm(p - c));
      }
    }
    return spread;
  }

  absl::Status SplitForMass(int depth, uint64_t start, uint64_t x, uint64_t y, int state) {
    RETURN_IF_ERROR(Checkpoint());
    const int g = curve_.grid();
    const uint64_t span = curve_.Span(depth + 1);
    const double h = 1.0 / curve_.PowG(depth + 1);
    NoteDepth(depth + 1, (x * g + 0.5) * h, (y * g + 0.5) * h);
    double masses[9];  // by grid position, [dx * g + dy]
    RETURN_IF_ERROR(CellMassesOnGrid(surface_, density_, decision_estimator_, x * g * h, y * g * h, h,
                                     g, masses));
    for (int c = 0; c < curve_.arity(); ++c) {
      const Curve::Child& ch = curve_.ChildOf(state, c);
      const uint64_t cx = x * g + ch.dx, cy = y * g + ch.dy;
      const uint64_t child_start = start + c * span;
      const double mass = masses[ch.dx * g + ch.dy];
      if (mass > limit_ && depth + 1 < options_.depth_cap) {
        RETURN_IF_ERROR(SplitForMass(depth + 1, child_start, cx, cy, ch.state));
        continue;
      }
      if (mass > limit_) RecordMassHit(cx * h, cy * h, h, mass);
      RETURN_IF_ERROR(Keep(child_start, mass));
    }
    return absl::OkStatus();
  }

  // Sets the grade's mass limit and forgets the previous grade's mass hits.
  void StartMassPass(const CurveTree& prev, int grade) {
    limit_ = options_.rho * prev.base_mass_ / std::ldexp(1.0, grade);
    report_.mass_capped_leaves = 0;
    report_.worst.erase(std::remove_if(report_.worst.begin(), report_.worst.end(),
                                       [](const DepthCapHit& h) {
                                         return h.test == DepthCapHit::Test::kMass;
                                       }),
                        report_.worst.end());
  }

  void RecordMassHit(double u0, double v0, double size, double mass) {
    ++report_.mass_capped_leaves;
    RecordHit({DepthCapHit::Test::kMass, u0, v0, size, mass, limit_}, &report_);
  }

  absl::Status Keep(uint64_t start, double mass) {
    if (starts_.size() >= options_.max_leaves) {
      // Say where the tree was growing deepest: usually a singularity.
      return absl::ResourceExhaustedError(absl::StrCat(
          LeafBudgetError(options_.max_leaves).message(),
          absl::StrFormat(". The deepest split so far is at depth %d near (u,v) = (%.9g, %.9g)%s",
                          deepest_, deepest_u_, deepest_v_,
                          deepest_ >= 20 ? "; the surface may be singular there" : "")));
    }
    starts_.push_back(start);
    masses_.push_back(mass);
    return absl::OkStatus();
  }

  // Asks the caller whether to go on, every BuildControl::kCheckInterval cells.
  absl::Status Checkpoint() {
    if (!control_.check || ++cells_since_check_ < BuildControl::kCheckInterval) {
      return absl::OkStatus();
    }
    cells_since_check_ = 0;
    return control_.check();
  }

  void NoteDepth(int depth, double u, double v) {
    if (depth <= deepest_) return;
    deepest_ = depth;
    deepest_u_ = u;
    deepest_v_ = v;
  }

  // The cell of leaf l of starts_.
  CurveTree::Cell CellOf(size_t l) const {
    return CurveTree::CellOfRange(curve_, starts_[l],
                                  l + 1 < starts_.size() ? starts_[l + 1] : curve_.Span(0));
  }

  const Surface& surface_;
  const Density& density_;
  const CurveTreeOptions& options_;
  const BuildControl& control_;
  uint64_t cells_since_check_ = 0;
  const Curve& curve_;
  const AreaEstimator decision_estimator_;
  double limit_ = 0;
  int deepest_ = 0;
  double deepest_u_ = 0.5, deepest_v_ = 0.5;
  std::vector<uint64_t> starts_;
  std::vector<double> masses_;
  PrecisionReport report_;
};

namespace {

absl::StatusOr<CurveTreeOptions> ResolveOptions(const Surface& surface, CurveTreeOptions options) {
  const Curve& curve = Curve::Get(options.curve);
  if (!(options.tolerance >= 0) || !std::isfinite(options.tolerance)) {
    return absl::InvalidArgumentError(
        absl::StrFormat("tolerance must be >= 0 (0 = automatic), got %g", options.tolerance));
  }
  if (options.depth_cap < 0 || options.depth_cap > curve.max_depth()) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "depth cap must be in [0, %d] for the %s curve (0 = deepest), got %d", curve.max_depth(),
        CurveName(options.curve), options.depth_cap));
  }
  if (!(options.rho > 0) || !std::isfinite(options.rho)) {
    return absl::InvalidArgumentError(absl::StrFormat("rho must be > 0, got %g", options.rho));
  }
  if (options.max_leaves == 0) return absl::InvalidArgumentError("max_leaves must be >= 1");
  if (options.depth_cap == 0) options.depth_cap = curve.max_depth();
  if (options.tolerance == 0) {
    constexpr int kGrid = 16;
    Vec3 lo{INFINITY, INFINITY, INFINITY}, hi{-INFINITY, -INFINITY, -INFINITY};
    for (int i = 0; i <= kGrid; ++i) {
      for (int j = 0; j <= kGrid; ++j) {
        const double u = static_cast<double>(i) / kGrid, v = static_cast<double>(j) / kGrid;
        const Vec3 p = surface.Point(u, v);
        if (!IsFinite(p)) {
          return SurfaceNotFiniteError(u, v);
        }
        lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
        hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
      }
    }
    const double diagonal = Norm(hi - lo);
    if (!(diagonal > 0)) {
      return absl::InvalidArgumentError(
          "the surface maps the whole parameter box to one point; it has no area to sample");
    }
    options.tolerance = 0.01 * diagonal;
  }
  return options;
}

}  // namespace

int CurveTree::GradeFor(uint64_t count) {
  int g = 0;
  while (g < 63 && (uint64_t{1} << g) < count) ++g;
  return g;
}

absl::StatusOr<std::shared_ptr<const CurveTree>> CurveTree::Build(const Surface& surface,
                                                                  const Density& density,
                                                                  const CurveTreeOptions& options,
                                                                  int grade,
                                                                  const BuildControl& control) {
  if (grade < 0 || grade > 62) {
    return absl::InvalidArgumentError(absl::StrFormat("tree grade must be in [0, 62], got %d", grade));
  }
  ASSIGN_OR_RETURN(const CurveTreeOptions resolved, ResolveOptions(surface, options));
  auto tree = std::shared_ptr<CurveTree>(new CurveTree());
  tree->curve_ = &Curve::Get(resolved.curve);
  tree->options_ = resolved;
  Builder builder(surface, density, tree->options_, control);
  RETURN_IF_ERROR(builder.BuildGeometric());
  RETURN_IF_ERROR(builder.Finish(tree.get()));
  tree->base_mass_ = tree->total_mass();
  if (grade == 0) return std::shared_ptr<const CurveTree>(std::move(tree));
  return tree->Refined(surface, density, grade, control);
}

absl::StatusOr<std::shared_ptr<const CurveTree>> CurveTree::Refined(const Surface& surface,
                                                                    const Density& density,
                                                                    int grade,
                                                                    const BuildControl& control) const {
  if (grade < grade_ || grade > 62) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "cannot refine a grade-%d tree to grade %d; grades only grow, up to 62", grade_, grade));
  }
  // The copy is private until returned, so the passes may update it in place.
  auto tree = std::shared_ptr<CurveTree>(new CurveTree(*this));
  for (int g = grade_ + 1; g <= grade; ++g) {
    Builder builder(surface, density, tree->options_, control);
    builder.set_report(tree->precision_);
    if (builder.PassSplits(*tree, g)) {
      RETURN_IF_ERROR(builder.RefinePass(*tree, g));
      RETURN_IF_ERROR(builder.Finish(tree.get()));
    } else {
      builder.ReportMassCaps(*tree, g);
      tree->precision_ = builder.report();
    }
    tree->grade_ = g;
  }
  tree->starts_.shrink_to_fit();
  tree->mass_end_.shrink_to_fit();
  return std::shared_ptr<const CurveTree>(std::move(tree));
}

CurveTree::Cell CurveTree::CellOfRange(const Curve& curve, uint64_t start, uint64_t end) {
  const int depth = curve.DepthOfSpan(end - start);
  uint64_t x, y;
  int state = Curve::kRootState;
  curve.Descend(curve.Prefix(start, depth), depth, &x, &y, &state);
  const double h = 1.0 / curve.PowG(depth);
  return {x * h, y * h, h, depth, state, x, y};
}

CurveTree::Cell CurveTree::LeafCell(size_t l) const {
  return CellOfRange(*curve_, starts_[l], leaf_end(l));
}

size_t CurveTree::LeafAt(uint64_t index) const {
  return static_cast<size_t>(std::upper_bound(starts_.begin(), starts_.end(), index) -
                             starts_.begin()) -
         1;
}

void CurveTree::ComputeDepthRange() {
  min_depth_ = curve_->max_depth();
  max_depth_ = 0;
  for (size_t l = 0; l < starts_.size(); ++l) {
    const int d = leaf_depth(l);
    min_depth_ = std::min(min_depth_, d);
    max_depth_ = std::max(max_depth_, d);
  }
}

}  // namespace sfc
