#include "core/curve_tree.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "base/status_macros.h"
#include "core/area_estimator.h"
#include "core/vector_math.h"

namespace sfc {
namespace {

constexpr int kNeverFails = 63;
// The least rho at which an exact model skips the error test's children
// (Refine): the default, where the full test's rounding noise fails at no
// grade. At rho 1e-12 it split cells (a STEP box at 10^5 samples: 77 762
// leaves with the full test, 37 826 with the shortcut); the rho at which it
// starts to was not measured.
constexpr double kExactLeastRho = 1;
// Fixed-point scale of the running masses: S_base is 2^56 units.
constexpr int kMassBits = 56;
static_assert(CurveTree::kSmallestMass == 0x1p-1022 * static_cast<double>(uint64_t{1} << kMassBits),
              "the mass unit of the least total mass is the least normal double");

void RecordHit(const DepthCapHit& hit, std::vector<DepthCapHit>* worst) {
  auto ratio = [](const DepthCapHit& h) { return h.limit > 0 ? h.measured / h.limit : INFINITY; };
  if (worst->size() == PrecisionReport::kMaxReported && ratio(hit) <= ratio(worst->back())) return;
  auto pos = std::upper_bound(worst->begin(), worst->end(), hit,
                              [&](const auto& a, const auto& b) { return ratio(a) > ratio(b); });
  worst->insert(pos, hit);
  if (worst->size() > PrecisionReport::kMaxReported) worst->pop_back();
}

// When the budget allows at least this many leaves a sample, the count is not
// what fills it: the surface's or density's detail is (a leaf of the error
// test carries down to kRoughFloor of a sample only where its model misses).
constexpr double kLeavesPerSampleNotCount = 16;

// The leaf budget's error for a tree of `grade` (-1: stage 1, where the count
// plays no part yet), saying what to change.
absl::Status LeafBudgetError(uint64_t max_leaves, int grade) {
  const std::string budget = absl::StrFormat(
      "the curve tree needs more than %d leaves (the max_leaves budget, %d bytes at %d bytes a "
      "leaf)",
      max_leaves, max_leaves * CurveTree::kBytesPerLeaf, CurveTree::kBytesPerLeaf);
  if (grade < 0) {
    return absl::ResourceExhaustedError(absl::StrCat(
        budget,
        " to follow the surface's shape alone, whatever the count: its detail is finer than the "
        "tolerance over the budget; raise the tolerance, lower the depth cap, smooth or simplify "
        "the surface, or raise the budget"));
  }
  const double samples = std::ldexp(1.0, grade);
  if (static_cast<double>(max_leaves) >= kLeavesPerSampleNotCount * samples) {
    return absl::ResourceExhaustedError(absl::StrCat(
        budget,
        absl::StrFormat(
            ", %.3g leaves a sample for the 2^%d samples it is graded for, so the count is not "
            "what needs them: the surface or density has more detail than the budget resolves (a "
            "steep, rough or fast-oscillating term, or a singularity); smooth or simplify the "
            "spec, raise the tolerance or rho, lower the depth cap, or raise the budget",
            static_cast<double>(max_leaves) / samples, grade)));
  }
  return absl::ResourceExhaustedError(absl::StrCat(
      budget,
      "; ask for fewer samples (a smaller count: the tree is sized for the whole set, also for "
      "a range of it), raise the tolerance or rho, lower the depth cap, or raise the budget"));
}

double TriangleArea(const Vec3& a, const Vec3& b, const Vec3& c) {
  return 0.5 * Norm(Cross(b - a, c - a));
}

// N^(1/2) and N^(1/4) by square roots: correctly rounded on every machine,
// and cheap in the tree's inner loop.
double RootN(double n) { return std::sqrt(n); }
double FourthRootN(double n) { return std::sqrt(std::sqrt(n)); }
static_assert(CurveTree::kErrorFloorPower == 0.5, "the floors are square roots (RootN)");

// The leaf's error allowance in samples at grade g (file comment of
// curve_tree.h), and whether the leaf carries enough samples to be split.
bool FailsAt(int g, double error, double mass, double base, double rho) {
  const double n = std::ldexp(1.0, g);
  const double mu = mass / base;
  return mu * n >= std::max(CurveTree::kMinSamples, CurveTree::kErrorFloor * RootN(n)) &&
         error / base * n > rho * CurveTree::kErrorShare * FourthRootN(n) * mu;
}

// The smallest grade g at which the leaf carries scale * N^(1/2) samples
// (N = 2^g, so the condition only tightens as g grows).
int SamplesGrade(double mass, double base, double scale) {
  double n = 1;  // 2^g, exactly
  for (int g = 0; g <= 62; ++g, n *= 2) {
    if (mass / base * n >= std::max(CurveTree::kMinSamples, scale * RootN(n))) return g;
  }
  return kNeverFails;
}

// The smallest grade at which the leaf carries kRoughFloor samples: where a
// leaf's model misses a fixed share of its own mass (a step, a kink at a zero
// or a singular line cuts it), it is examined down to this floor, which does
// not grow with N, so the error along the feature falls like N^(-1/2).
int RoughGrade(double mass, double base) {
  double n = 1;  // 2^g, exactly
  for (int g = 0; g <= 62; ++g, n *= 2) {
    if (mass / base * n >= CurveTree::kRoughFloor) return g;
  }
  return kNeverFails;
}

// The smallest grade at which a leaf's hidden-mass bound is worth
// kHiddenFloor samples (docs/ALGORITHM.md, "Features narrower than the
// probes").
int HiddenGrade(double hidden, double base) {
  if (!(hidden > 0)) return kNeverFails;
  double n = 1;  // 2^g, exactly
  for (int g = 0; g <= 62; ++g, n *= 2) {
    if (hidden / base * n >= CurveTree::kHiddenFloor) return g;
  }
  return kNeverFails;
}

// a + b, sticking at UINT64_MAX.
uint64_t SaturatingAdd(uint64_t a, uint64_t b) { return a > UINT64_MAX - b ? UINT64_MAX : a + b; }

// The smallest grade in [0, 62] at which the leaf fails, kNeverFails if none.
// Both conditions are monotone in g, so a binary search finds it.
int FailGrade(double error, double mass, double base, double rho) {
  if (!(error > 0) || !(mass > 0)) return kNeverFails;
  if (!FailsAt(62, error, mass, base, rho)) return kNeverFails;
  int lo = 0, hi = 62;
  while (lo < hi) {
    const int mid = (lo + hi) / 2;
    if (FailsAt(mid, error, mass, base, rho)) {
      hi = mid;
    } else {
      lo = mid + 1;
    }
  }
  return lo;
}

}  // namespace

// Holds what one build or refinement needs; not thread-safe, one per call.
class CurveTree::Builder {
 public:
  Builder(const Surface& surface, const Density& density, const CurveTreeOptions& options,
          const BuildControl& control)
      : surface_(surface),
        density_(density),
        options_(options),
        control_(control),
        curve_(Curve::Get(options.curve)),
        order_(density.NeedsCurvature() ? 2 : 1),
        affine_(surface.IsAffine()) {}

  // One cell's mass estimate and model (file comment of curve_tree.h).
  struct CellEval {
    double mass = 0;
    double area = 0;   // the same for delta = 1 (quadrature of the area element)
    double values[9];  // quadratic: m at the Gauss nodes; piecewise: sub-square masses
    double delta[9];   // the density at the nodes (NaN where singular)
    AxisWarp warp[2] = {kNoWarp, kNoWarp};  // the quadratic's power laws (LeafModel::warp)
    bool piecewise = false;
    bool singular = false;  // the area element is not finite at a node
    bool varies = false;    // ... or varies by more than 2x over them
    double area_ratio = 1;  // the largest over the smallest at the nodes
    bool warped() const { return warp[0].power != 1 || warp[1].power != 1; }
  };

  // Power laws are read at h 2^-kWarpProbeNear and h 2^-kWarpProbeFar from
  // the line, and warped for |p| >= kMinWarpPower. A line inside the cell is
  // located to 1e-15 of the cell in at most kInteriorSearchSteps, and its
  // exponents on the two sides may differ by kInteriorPowerMismatch.
  static constexpr int kWarpProbeNear = 12, kWarpProbeFar = 20;
  static constexpr double kMinWarpPower = 0.2;
  static constexpr int kInteriorSearchSteps = 80;
  static constexpr double kInteriorPowerMismatch = 0.1;
  // Edges are probed where the area element varies by more than this over the
  // nodes: t^(-1/3) (a superellipsoid's poles) varies by 2x, t^(+-0.2) by 1.5x.
  static constexpr double kWarpProbeRatio = 1.25;

  // Stage 1: the paper's PopulateCurveTree from the root; fills starts_ and
  // masses_ with the stage-1 leaves.
  absl::Status BuildGeometric() { return Geometric(0, 0, 0, 0, Curve::kRootState); }

  // Stage 2 from the cell (depth, x, y) whose curve range starts at `start`:
  // appends its leaves at `grade`.
  // `rough_parent`: the cell's parent failed the rough test (stage-1 leaves:
  // true, as stage 1 tests no mass; a refined leaf: as recorded,
  // leaf_rough_parent).
  // `replaces_leaf`: the cell is a leaf of the tree being refined, whose
  // hidden-mass bound (in the sum it starts from) it takes out.
  absl::Status RefineCell(int depth, uint64_t start, uint64_t x, uint64_t y, int state,
                          bool rough_parent, bool replaces_leaf = false) {
    ASSIGN_OR_RETURN(const CellEval eval, Evaluate(depth, x, y));
    if (replaces_leaf && density_.Bounds()) {
      const double h = 1.0 / curve_.PowG(depth);
      const uint64_t old = ToFixed(HiddenMass(eval, x * h, y * h, h));
      // A saturated sum stays so (it is refused either way).
      if (hidden_units_ != UINT64_MAX) hidden_units_ -= std::min(old, hidden_units_);
    }
    return Refine(depth, start, x, y, state, eval, rough_parent);
  }

  // The hidden-mass sum of the tree being refined (set before RefineCell).
  void set_hidden_units(uint64_t units) { hidden_units_ = units; }

  // Stage 1's hidden-mass refinement (docs/ALGORITHM.md, "Features narrower
  // than the probes"): while a stage-1 leaf's hidden-mass bound exceeds
  // kStage1HiddenShare of the stage's mass, it is replaced by its children,
  // in rounds (each round's threshold from the mass of the round before), so
  // that a feature no probe saw counts in S_base. At most
  // kStage1HiddenLeaves leaves are added; what is left is stage 2's and the
  // final check's. Nothing changes for densities that do not bound
  // themselves or leaves that hide nothing.
  absl::Status RefineHiddenStage1() {
    if (!density_.Bounds()) return absl::OkStatus();
    const uint64_t budget = std::min<uint64_t>(
        options_.max_leaves, stage1_starts_.size() + CurveTree::kStage1HiddenLeaves);
    bool changed = false;
    for (;;) {
      double mass = 0;
      for (const double m : stage1_masses_) mass += m;
      const double limit = CurveTree::kStage1HiddenShare * mass;
      std::vector<uint64_t> starts;
      std::vector<double> masses, hidden;
      starts.reserve(stage1_starts_.size());
      bool split = false;
      const size_t n = stage1_starts_.size();
      for (size_t l = 0; l < n; ++l) {
        const uint64_t end = l + 1 < n ? stage1_starts_[l + 1] : curve_.Span(0);
        const CurveTree::Cell cell = CellOfRange(curve_, stage1_starts_[l], end);
        const bool room = starts.size() + curve_.arity() + (n - l - 1) <= budget;
        if (!(stage1_hidden_[l] > limit) || cell.depth >= options_.depth_cap ||
            cell.depth >= curve_.max_depth() || !room) {
          starts.push_back(stage1_starts_[l]);
          masses.push_back(stage1_masses_[l]);
          hidden.push_back(stage1_hidden_[l]);
          continue;
        }
        split = true;
        const int depth = cell.depth + 1;
        const uint64_t span = curve_.Span(depth);
        const int g = curve_.grid();
        const double h = 1.0 / curve_.PowG(depth);
        for (int c = 0; c < curve_.arity(); ++c) {
          const Curve::Child& ch = curve_.ChildOf(cell.state, c);
          const uint64_t x = cell.x * g + ch.dx, y = cell.y * g + ch.dy;
          NoteDepth(depth, (x + 0.5) * h, (y + 0.5) * h);
          ASSIGN_OR_RETURN(const CellEval eval, Evaluate(depth, x, y));
          starts.push_back(stage1_starts_[l] + c * span);
          masses.push_back(eval.mass);
          hidden.push_back(HiddenMass(eval, x * h, y * h, h));
        }
      }
      if (!split) break;
      changed = true;
      stage1_starts_ = std::move(starts);
      stage1_masses_ = std::move(masses);
      stage1_hidden_ = std::move(hidden);
    }
    if (changed) {
      stage1_mass_ = 0;
      for (const double m : stage1_masses_) stage1_mass_ += m;
    }
    return absl::OkStatus();
  }

  void StartStage2(double base, int grade, size_t expected_leaves) {
    base_ = base;
    grade_ = grade;
    stage2_ = true;
    starts_.clear();
    masses_.clear();
    models_.clear();
    errors_.clear();
    info_.clear();
    Reserve(expected_leaves);
  }

  // Copies leaf l of `prev` unchanged.
  absl::Status CopyLeaf(const CurveTree& prev, size_t l) {
    RETURN_IF_ERROR(Grow());
    starts_.push_back(prev.starts_[l]);
    masses_.push_back(prev.mass_end_[l] - (l == 0 ? 0 : prev.mass_end_[l - 1]));
    models_.push_back(prev.models_[l]);
    errors_.push_back(prev.errors_[l]);
    info_.push_back(prev.info_[l]);
    return absl::OkStatus();
  }

  // Stage-1 leaves, as (start, mass) pairs.
  const std::vector<uint64_t>& stage1_starts() const { return stage1_starts_; }
  double stage1_mass() const { return stage1_mass_; }
  double stage1_area() const { return stage1_area_; }

  // Installs the leaves into `tree`.
  absl::Status Finish(CurveTree* tree) {
    if (options_.estimator == AreaEstimator::kTriangle) RETURN_IF_ERROR(ComputeTriangleMasses());
    tree->starts_ = std::move(starts_);
    tree->models_ = std::move(models_);
    tree->errors_ = std::move(errors_);
    tree->info_ = std::move(info_);
    tree->mass_end_ = std::move(masses_);
    // In place for large arrays (base/pod_array.h): bytes() counts what is kept.
    tree->starts_.shrink_to_fit();
    tree->models_.shrink_to_fit();
    tree->errors_.shrink_to_fit();
    tree->info_.shrink_to_fit();
    tree->mass_end_.shrink_to_fit();
    uint64_t sum = 0;
    for (uint64_t& m : tree->mass_end_) {
      if (m > UINT64_MAX - sum) {
        return absl::InvalidArgumentError(
            "the surface's mass estimates grew more than 256-fold under refinement; the "
            "parameterisation is too singular for the estimates to converge (reparameterise it)");
      }
      m = sum += m;
    }
    if (sum == 0) {
      return absl::InvalidArgumentError(
          "the density integrates to 0 over the surface; it must be positive somewhere (check "
          "the density, or add a floor)");
    }
    tree->hidden_units_ = hidden_units_;
    tree->ComputeDepthRange();
    tree->ComputeReport();
    const double share = static_cast<double>(hidden_units_) / static_cast<double>(sum);
    tree->precision_.hidden_share = share;
    if (share > CurveTree::kHiddenShare && control_.refuse_hidden) return HiddenError(share);
    return absl::OkStatus();
  }

  // The leaves may hide too much mass (docs/ALGORITHM.md, "Features narrower
  // than the probes"): says how much, where, and what to change.
  absl::Status HiddenError(double share) const {
    const CurveTree::Cell& w = worst_hidden_cell_;
    std::string where;
    if (worst_hidden_ > 0) {
      where = absl::StrFormat(
          ", the most in the cell u in [%.9g, %.9g], v in [%.9g, %.9g] (depth %d), and all in u "
          "in [%.9g, %.9g], v in [%.9g, %.9g]",
          w.u0, w.u0 + w.size, w.v0, w.v0 + w.size, w.depth, hidden_box_[0], hidden_box_[1],
          hidden_box_[2], hidden_box_[3]);
    }
    const std::string amount = share >= 1
                                   ? absl::StrFormat("%.3g times the mass it measured", share)
                                   : absl::StrFormat("%.3g%% of the mass it measured", 100 * share);
    return absl::InvalidArgumentError(absl::StrFormat(
        "the density has features narrower than the curve tree can see: its interval bounds "
        "allow up to %s (more than %.3g%%) in parts of leaves where it may exceed %g times "
        "every value the leaves' probes saw%s; the samples would miss that mass. Widen or "
        "smooth the narrow features (or give them a floor within %g times their peak), ask for "
        "more samples, or raise the depth cap (%d) if the tree reached it",
        amount, 100 * CurveTree::kHiddenShare, CurveTree::kHiddenFactor, where,
        CurveTree::kHiddenFactor, options_.depth_cap));
  }

  const PrecisionReport& report() const { return report_; }
  void set_report(const PrecisionReport& report) { report_ = report; }

  // Stage 1 splits for flatness down to this depth only (4096 cells for
  // Hilbert, 6561 for the 3x3 curves).
  int BaseDepth() const { return curve_.grid() == 2 ? 6 : 4; }

 private:
  absl::Status Geometric(int depth, uint64_t start, uint64_t x, uint64_t y, int state) {
    RETURN_IF_ERROR(Checkpoint());
    const double h = 1.0 / curve_.PowG(depth);
    const double u0 = x * h, v0 = y * h;
    NoteDepth(depth, u0 + h / 2, v0 + h / 2);
    ASSIGN_OR_RETURN(const double spread, CellSpread(u0, v0, h));
    const bool wants_split = spread > options_.tolerance;
    // Deeper than the base depth the flatness test runs in stage 2, where a
    // leaf too light to matter stops it.
    if (wants_split && depth < BaseDepth() && depth < options_.depth_cap) {
      const uint64_t span = curve_.Span(depth + 1);
      const int g = curve_.grid();
      for (int c = 0; c < curve_.arity(); ++c) {
        const Curve::Child& ch = curve_.ChildOf(state, c);
        RETURN_IF_ERROR(
            Geometric(depth + 1, start + c * span, x * g + ch.dx, y * g + ch.dy, ch.state));
      }
      return absl::OkStatus();
    }
    if (wants_split && depth >= options_.depth_cap) {
      ++report_.geometry_capped_leaves;
      RecordHit({DepthCapHit::Test::kGeometry, u0, v0, h, spread, options_.tolerance},
                &report_.worst);
    }
    if (stage1_starts_.size() >= options_.max_leaves) return BudgetError();
    ASSIGN_OR_RETURN(const CellEval eval, Evaluate(depth, x, y));
    const bool singular = eval.piecewise;
    stage1_starts_.push_back(start);
    stage1_mass_ += eval.mass;
    if (density_.Bounds()) {
      stage1_masses_.push_back(eval.mass);
      stage1_hidden_.push_back(HiddenMass(eval, u0, v0, h));
    }
    stage1_area_ += singular ? INFINITY : eval.area;
    return absl::OkStatus();
  }

  // AssessSubdivision: the largest distance from f(centre) to f at the 4
  // corners and 4 edge midpoints of the cell, the 9 points from one Points
  // call (Point's bits, one dispatch).
  absl::StatusOr<double> CellSpread(double u0, double v0, double h) const {
    double us[9], vs[9], x[9], y[9], z[9];
    for (int i = 0; i <= 2; ++i) {
      for (int j = 0; j <= 2; ++j)
        us[3 * i + j] = u0 + i * (h / 2), vs[3 * i + j] = v0 + j * (h / 2);
    }
    surface_.Points(us, vs, 9, x, y, z);
    const Vec3 c{x[4], y[4], z[4]};
    double spread = 0;
    for (int k = 0; k < 9; ++k) {
      const Vec3 p{x[k], y[k], z[k]};
      if (!IsFinite(p)) return SurfaceNotFiniteError(us[k], vs[k]);
      spread = std::max(spread, Norm(p - c));
    }
    return spread;
  }

  // The cell's model: m at the 3 x 3 Gauss nodes. Where the area element
  // varies over them, each edge is probed for a power law (EdgeWarp) and the
  // nodes move to the warped coordinates; where the quadrature is still not
  // to be trusted, a power law about a line through the cell is looked for
  // (InteriorWarp), and failing that the masses of the mapped g x g
  // sub-squares are used instead.
  absl::StatusOr<CellEval> Evaluate(int depth, uint64_t x, uint64_t y) {
    RETURN_IF_ERROR(Checkpoint());
    const double h = 1.0 / curve_.PowG(depth);
    const double u0 = x * h, v0 = y * h;
    AxisWarp warp[2] = {kNoWarp, kNoWarp};
    ASSIGN_OR_RETURN(CellEval eval, EvaluateNodes(u0, v0, h, warp));
    if (eval.singular || !(eval.area_ratio <= kWarpProbeRatio)) {
      ASSIGN_OR_RETURN(warp[0], EdgeWarp(u0, v0, h, 0));
      ASSIGN_OR_RETURN(warp[1], EdgeWarp(u0, v0, h, 1));
      if (warp[0].power != 1 || warp[1].power != 1) {
        ASSIGN_OR_RETURN(CellEval warped, EvaluateNodes(u0, v0, h, warp));
        if (!warped.singular) eval = warped;
      }
    }
    // A smooth patch has nearly constant (warped) area element on a small
    // cell; only where it varies by 2x can the quadrature be far off.
    if (!eval.singular && !eval.varies) return eval;
    double sub[9];
    ASSIGN_OR_RETURN(const double triangles, SubSquareMasses(u0, v0, h, eval.delta, sub));
    // Either way: a node beside a blow-up line also overshoots.
    const bool misses =
        triangles > kSingularExcess * eval.mass || eval.mass > kSingularExcess * triangles;
    if (!eval.singular && !misses) return eval;
    // The quadrature misses mass: a singular line inside the cell?
    bool interior = false;
    for (int axis = 0; axis < 2; ++axis) {
      if (warp[axis].power != 1) continue;
      ASSIGN_OR_RETURN(warp[axis], InteriorWarp(u0, v0, h, axis));
      interior = interior || warp[axis].power != 1;
    }
    if (interior) {
      ASSIGN_OR_RETURN(CellEval warped, EvaluateNodes(u0, v0, h, warp));
      if (!warped.singular && !(triangles > kSingularExcess * warped.mass && warped.varies)) {
        return warped;
      }
    }
    std::copy(sub, sub + 9, eval.values);
    eval.mass = triangles;
    eval.piecewise = true;
    eval.warp[0] = eval.warp[1] = kNoWarp;
    return eval;
  }

  // m at the 3 x 3 Gauss nodes of the cell in the coordinates warped by
  // `warp` (the values include the warp's slopes, so their Gauss sum is the
  // cell's mass), with `singular` where the area element is not finite at a
  // node and `varies` where it varies by more than 2x.
  absl::StatusOr<CellEval> EvaluateNodes(double u0, double v0, double h, const AxisWarp warp[2]) {
    double us[3], vs[3], su[3], sv[3];
    for (int i = 0; i < 3; ++i) {
      const double s = WarpNode(warp[0], kGaussNode[i]), t = WarpNode(warp[1], kGaussNode[i]);
      us[i] = u0 + Warp(warp[0], s) * h, su[i] = WarpSlope(warp[0], s);
      vs[i] = v0 + Warp(warp[1], t) * h, sv[i] = WarpSlope(warp[1], t);
    }
    SurfaceJet jets[9];
    surface_.JetGrid(us, 3, vs, 3, order_, jets);
    CellEval eval;
    eval.warp[0] = warp[0], eval.warp[1] = warp[1];
    double amin = INFINITY, amax = 0, gauss = 0;
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) {
        const int k = 3 * i + j;
        const SurfaceJet& jet = jets[k];
        if (!IsFinite(jet.p)) return SurfaceNotFiniteError(us[i], vs[j]);
        double area;
        const SurfacePoint point = PointFromJet(jet, us[i], vs[j], order_ == 2, &area);
        area *= su[i] * sv[j];
        if (!std::isfinite(area)) {
          // A singular line through the node: the curvatures are unusable,
          // delta is taken from the neighbouring nodes (SubSquareMasses).
          eval.singular = true;
          eval.delta[k] = NAN;
          eval.values[k] = 0;
          continue;
        }
        eval.delta[k] = density_.Value(point);
        RETURN_IF_ERROR(CheckDensityValue(eval.delta[k], us[i], vs[j]));
        amin = std::min(amin, area);
        amax = std::max(amax, area);
        eval.area += kGaussWeight[i] * kGaussWeight[j] * area * h * h;
        eval.values[k] = eval.delta[k] * area;
        gauss += kGaussWeight[i] * kGaussWeight[j] * eval.values[k];
      }
    }
    eval.mass = gauss * h * h;
    eval.area_ratio = amax / amin;
    eval.varies = eval.singular || !(amax <= 2 * amin);
    return eval;
  }

  // The mass density m = delta |f_u x f_v| at leaf coordinate x along the
  // cell's axis `axis`, across it at the cell's middle; +infinity where the
  // surface or its area element is not finite.
  absl::StatusOr<double> AxisDensity(double u0, double v0, double h, int axis, double x) const {
    const double u = axis == 0 ? u0 + x * h : u0 + h / 2, v = axis == 0 ? v0 + h / 2 : v0 + x * h;
    // The searches close in on the line itself, where a pole is not finite.
    double m;
    MassDensityGrid(surface_, density_, &u, 1, &v, 1, &m);
    return m;
  }

  // The exponent p in m ~ t^p at distance t from the singular point `centre`
  // of the axis, on the side `side` (-1 below, +1 above), read off m at two
  // distances; NaN where they do not tell.
  absl::StatusOr<double> PowerBeside(double u0, double v0, double h, int axis, double centre,
                                     int side) const {
    double t[2], m[2];
    for (int q = 0; q < 2; ++q) {
      const double x = centre + side * std::ldexp(1.0, q == 0 ? -kWarpProbeNear : -kWarpProbeFar);
      // The distance as rounded in parameter units, over the cell's side.
      const double origin = axis == 0 ? u0 : v0;
      t[q] = std::fabs((origin + x * h) - (origin + centre * h)) / h;
      ASSIGN_OR_RETURN(m[q], AxisDensity(u0, v0, h, axis, x));
      if (!(t[q] > 0) || !std::isfinite(m[q]) || !(m[q] > 0)) return NAN;
    }
    if (!(t[1] < t[0])) return NAN;
    return math::Log(m[1] / m[0]) / math::Log(t[1] / t[0]);
  }

  // The power law of the cell's axis `axis` toward an edge (LeafModel::warp,
  // AxisWarp with centre 0 or 1): an edge where m blows up (p < 0) or
  // vanishes (p > 0) gets k = 1 / (1 + p), which makes the warped density
  // m(W(s)) W'(s) ~ s^(k (1 + p) - 1) constant at the edge. kNoWarp where
  // neither edge has such a power law.
  absl::StatusOr<AxisWarp> EdgeWarp(double u0, double v0, double h, int axis) const {
    double best_p = 0;
    int best_side = 0;
    for (int side = 0; side < 2; ++side) {
      ASSIGN_OR_RETURN(const double p, PowerBeside(u0, v0, h, axis, side, side == 0 ? 1 : -1));
      if (std::fabs(p) > std::fabs(best_p)) best_p = p, best_side = side;
    }
    return PowerLaw(best_p, best_side);
  }

  // The power law about a line through the cell's interior where m blows
  // up: its place found by a golden-section search for the largest m along
  // the axis, started from the largest of 16 evenly spaced values, and its
  // exponent the same on both sides. kNoWarp where there is none.
  absl::StatusOr<AxisWarp> InteriorWarp(double u0, double v0, double h, int axis) const {
    constexpr int kScan = 16;
    int top = 0;
    double top_m = -1;
    for (int i = 0; i < kScan; ++i) {
      ASSIGN_OR_RETURN(const double m, AxisDensity(u0, v0, h, axis, (i + 0.5) / kScan));
      if (m > top_m) top_m = m, top = i;
    }
    double lo = std::max(0.0, (top - 0.5) / kScan), hi = std::min(1.0, (top + 1.5) / kScan);
    const double ratio = (std::sqrt(5.0) - 1) / 2;
    double a = hi - ratio * (hi - lo), b = lo + ratio * (hi - lo);
    ASSIGN_OR_RETURN(double ma, AxisDensity(u0, v0, h, axis, a));
    ASSIGN_OR_RETURN(double mb, AxisDensity(u0, v0, h, axis, b));
    for (int it = 0; it < kInteriorSearchSteps && hi - lo > 1e-15; ++it) {
      if (ma >= mb) {
        hi = b, b = a, mb = ma, a = hi - ratio * (hi - lo);
        ASSIGN_OR_RETURN(ma, AxisDensity(u0, v0, h, axis, a));
      } else {
        lo = a, a = b, ma = mb, b = lo + ratio * (hi - lo);
        ASSIGN_OR_RETURN(mb, AxisDensity(u0, v0, h, axis, b));
      }
    }
    const float centre = static_cast<float>((lo + hi) / 2);
    const double margin = std::ldexp(1.0, -kWarpProbeNear + 1);
    if (!(centre > margin && centre < 1 - margin)) return kNoWarp;
    ASSIGN_OR_RETURN(const double below, PowerBeside(u0, v0, h, axis, centre, -1));
    ASSIGN_OR_RETURN(const double above, PowerBeside(u0, v0, h, axis, centre, 1));
    if (!(std::fabs(below - above) <= kInteriorPowerMismatch) || !(below + above < 0))
      return kNoWarp;
    AxisWarp warp = PowerLaw((below + above) / 2, 0);
    if (warp.power != 1) warp.centre = centre;
    return warp;
  }

  // The warp for m ~ t^p toward the edge `side` (0: low, 1: high): weaker
  // power laws are left to the quadratic; below -0.95 the mass would not be
  // finite, and above 8 the warp's own nodes crowd the far edge.
  static AxisWarp PowerLaw(double p, int side) {
    if (!(std::fabs(p) >= kMinWarpPower) || p < -0.95 || p > 8) return kNoWarp;
    return {static_cast<float>(1 / (1 + p)), static_cast<float>(side)};
  }

  // The masses of the g x g sub-squares of the cell, each the area of its
  // mapped quadrilateral (the mean of its two triangulations) times delta at
  // the Gauss node nearest its centre. Returns their sum.
  absl::StatusOr<double> SubSquareMasses(double u0, double v0, double h, const double delta[9],
                                         double sub[9]) const {
    const int g = curve_.grid();
    Vec3 p[16];
    for (int i = 0; i <= g; ++i) {
      for (int j = 0; j <= g; ++j) {
        const double u = i == g ? u0 + h : u0 + i * (h / g);
        const double v = j == g ? v0 + h : v0 + j * (h / g);
        p[i * (g + 1) + j] = surface_.Point(u, v);
        if (!IsFinite(p[i * (g + 1) + j])) return SurfaceNotFiniteError(u, v);
      }
    }
    double known = 0;
    int n_known = 0;
    for (int k = 0; k < 9; ++k) {
      if (std::isfinite(delta[k])) known += delta[k], ++n_known;
    }
    const double fallback = n_known > 0 ? known / n_known : 0;
    double total = 0;
    for (int i = 0; i < g; ++i) {
      for (int j = 0; j < g; ++j) {
        const Vec3& a = p[i * (g + 1) + j];
        const Vec3& b = p[(i + 1) * (g + 1) + j];
        const Vec3& c = p[(i + 1) * (g + 1) + j + 1];
        const Vec3& d = p[i * (g + 1) + j + 1];
        const double area = 0.5 * (TriangleArea(a, b, c) + TriangleArea(a, c, d) +
                                   TriangleArea(a, b, d) + TriangleArea(b, c, d));
        // Node index nearest the sub-square's centre along each axis.
        const int ni = g == 3 ? i : 2 * i, nj = g == 3 ? j : 2 * j;
        const double dk = delta[3 * ni + nj];
        sub[i * g + j] = area * (std::isfinite(dk) ? dk : fallback);
        total += sub[i * g + j];
      }
    }
    return total;
  }

  // Whether the leaf's model misses a fixed share of its mass, so that it and
  // its children are examined down to kRoughFloor: a quadratic that misses
  // more than rho kRoughShare (a step or a crease cuts the cell), or the
  // piecewise fallback, which spreads samples evenly inside its sub-squares
  // however the mass lies there (a blow-up line just beyond the cell's
  // edge). A warped model follows its line by construction; its error
  // shrinks with the leaf, and the error test governs it.
  bool IsRough(const CellEval& eval, double error) const {
    if (eval.piecewise) return true;
    if (eval.warped()) return false;
    return error > kRoughShare * options_.rho * eval.mass;
  }

  // What the children's nodes cannot see: a step or crease of m within
  // 0.056 of the cell's side from an edge lies beyond every child's Gauss
  // node. m at the cell's 4 corners and 4 edge midpoints is compared with
  // the quadratic's value there; where one differs from it by more than
  // kEdgeJump of the largest node value, the band beside that edge
  // (kEdgeBand of the cell) is counted as mis-modelled by that difference.
  // 0 for warped and piecewise models (their edges are singular lines).
  double EdgeError(const CellEval& eval, double u0, double v0, double h) const {
    if (eval.piecewise || eval.warped()) return 0.0;
    const double at[3] = {0, 0.5, 1};
    double us[3], vs[3], m[9];
    for (int i = 0; i < 3; ++i) us[i] = u0 + at[i] * h, vs[i] = v0 + at[i] * h;
    MassDensityGrid(surface_, density_, us, 3, vs, 3, m);
    double top = 0;
    for (int k = 0; k < 9; ++k) top = std::max(top, std::fabs(eval.values[k]));
    double worst = 0;
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) {
        // A pole or singular line on the edge (m infinite): the warps' business.
        if ((i == 1 && j == 1) || !std::isfinite(m[3 * i + j])) continue;
        const double gap = std::fabs(m[3 * i + j] - QuadraticAt(eval.values, at[i], at[j]));
        if (gap > kEdgeJump * top) worst = std::max(worst, gap);
      }
    }
    return worst * kEdgeBand * h * h;
  }

  // The leaf's hidden-mass bound (docs/ALGORITHM.md, "Features narrower
  // than the probes"): what the cell's mass may exceed its estimate by in the
  // parts where the density's interval upper bound (Density::UpperBound)
  // exceeds kHiddenFactor times the largest density its Gauss nodes saw and
  // a probe confirms it (BoundAbove), each part counted at its bound times
  // its share of the cell's area (the quadrature's). A part the density
  // cannot bound, and a cell whose area element is singular, count 0.
  double HiddenMass(const CellEval& eval, double u0, double v0, double h) const {
    if (!density_.Bounds() || eval.piecewise || eval.singular || !std::isfinite(eval.area) ||
        !(eval.area > 0)) {
      return 0;
    }
    double seen = 0;
    for (const double d : eval.delta) {
      if (d > seen) seen = d;  // NaN (a singular node) is skipped
    }
    const double limit = kHiddenFactor * seen;
    const double u1 = std::min(1.0, u0 + h), v1 = std::min(1.0, v0 + h);
    const double bound = density_.UpperBound(surface_, u0, u1, v0, v1);
    if (!(bound > limit) || !std::isfinite(bound)) return 0;
    int budget = kHiddenEvaluations;
    return BoundAbove(u0, u1, v0, v1, bound, 0, limit, &budget) / ((u1 - u0) * (v1 - v0)) *
           eval.area;
  }

  // The hidden parts are narrowed down by halving: each step bounds both
  // halves along u and both along v and keeps the cut whose parts above the
  // limit hold less, so a line along an axis is closed in on at 4 bounds a
  // level; at most kHiddenLevels levels and kHiddenEvaluations bounds a leaf.
  static constexpr int kHiddenLevels = 12;
  static constexpr int kHiddenEvaluations = 64;

  // Whether the density at one of the 3 x 3 cell centres of [u0, u1] x
  // [v0, v1] exceeds `limit` (or cannot be evaluated): a feature there,
  // seen. A bound above the limit that no probe of the narrowed part
  // confirms is interval arithmetic's overestimate, not a feature: where
  // terms cancel (x*x - 2*x*y + y*y, sin(u)^2 + cos(u)^2) its widening
  // shrinks only in proportion to the part, and the part would be split
  // without end.
  bool Confirmed(double u0, double u1, double v0, double v1, double limit) const {
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) {
        const absl::StatusOr<DensityAt> at = EvaluateDensity(
            surface_, density_, u0 + (u1 - u0) * (2 * i + 1) / 6, v0 + (v1 - v0) * (2 * j + 1) / 6);
        if (!at.ok() || !(at->delta <= limit)) return true;
      }
    }
    return false;
  }

  // The sum of UpperBound times parameter area over the parts of [u0, u1] x
  // [v0, v1] whose bound exceeds `limit`, given its own `bound` (> limit),
  // each narrowed part counted only when a probe in it confirms the bound
  // (Confirmed).
  double BoundAbove(double u0, double u1, double v0, double v1, double bound, int level,
                    double limit, int* budget) const {
    const double whole = bound * (u1 - u0) * (v1 - v0);
    if (level == kHiddenLevels || *budget < 4) {
      return Confirmed(u0, u1, v0, v1, limit) ? whole : 0.0;
    }
    *budget -= 4;
    const double um = u0 + (u1 - u0) / 2, vm = v0 + (v1 - v0) / 2;
    const double b[4] = {density_.UpperBound(surface_, u0, um, v0, v1),
                         density_.UpperBound(surface_, um, u1, v0, v1),
                         density_.UpperBound(surface_, u0, u1, v0, vm),
                         density_.UpperBound(surface_, u0, u1, vm, v1)};
    const auto above = [&](double x) { return x > limit && std::isfinite(x); };
    const auto part = [&](double x) { return above(x) ? x * (u1 - u0) * (v1 - v0) / 2 : 0.0; };
    const bool along_u = part(b[0]) + part(b[1]) <= part(b[2]) + part(b[3]);
    double sum = 0;
    for (int side = 0; side < 2; ++side) {
      const double x = along_u ? b[side] : b[2 + side];
      if (!above(x)) continue;
      if (along_u) {
        sum += BoundAbove(side == 0 ? u0 : um, side == 0 ? um : u1, v0, v1, x, level + 1, limit,
                          budget);
      } else {
        sum += BoundAbove(u0, u1, side == 0 ? v0 : vm, side == 0 ? vm : v1, x, level + 1, limit,
                          budget);
      }
    }
    return std::min(whole, sum);
  }

  // The parent model's integral over child (cx, cy) of its g x g grid.
  double ModelOverChild(const CellEval& eval, int cx, int cy, double h) const {
    const int g = curve_.grid();
    if (eval.piecewise) return eval.values[cx * g + cy];
    return h * h *
           QuadraticIntegral(eval.values, static_cast<double>(cx) / g,
                             static_cast<double>(cx + 1) / g, static_cast<double>(cy) / g,
                             static_cast<double>(cy + 1) / g, eval.warp);
  }

  absl::Status Refine(int depth, uint64_t start, uint64_t x, uint64_t y, int state,
                      const CellEval& eval, bool rough_parent) {
    const int g = curve_.grid();
    const double h = 1.0 / curve_.PowG(depth);
    // A leaf too light to fail at this grade is not examined: it keeps the
    // grade at which it must be (a pure function of the cell), and a later
    // refinement examines it then, as a fresh build would.
    // Below the error floor only the children of a rough leaf are examined:
    // a feature the parent's test did not see is too small to matter there.
    int fail = SamplesGrade(eval.mass, base_, kErrorFloor);
    // Steps are followed only in cells larger than the density asks.
    const bool follow_steps = h > density_.StepResolution();
    if (rough_parent && follow_steps) fail = std::min(fail, RoughGrade(eval.mass, base_));
    // The hidden-mass bound, found where the cell would otherwise stay a
    // leaf: a leaf whose bound is worth kHiddenFloor samples is examined and
    // split (docs/ALGORITHM.md, "Features narrower than the probes").
    double hidden = -1;
    int hidden_grade = kNeverFails;
    const auto find_hidden = [&] {
      if (hidden >= 0) return;
      hidden = HiddenMass(eval, x * h, y * h, h);
      hidden_grade = HiddenGrade(hidden, base_);
    };
    bool examine = fail <= grade_;
    if (!examine && depth < options_.depth_cap && density_.Bounds()) {
      find_hidden();
      examine = hidden_grade <= grade_;
    }
    double error = 0;
    bool rough = false;
    CellEval children[9];
    if (examine && depth < curve_.max_depth()) {
      // An exact model (affine_, a uniform density on the closed cell) has
      // no error for its children to show: they are evaluated only when the
      // flatness test splits the cell, and its error is 0. The full test
      // would find rounding noise between the model's integrals and the
      // children's quadrature (of the order of 1e-16 of the cell's mass),
      // which its allowance, scaled by rho, dwarfs at rho >= kExactLeastRho; at a
      // smaller rho the noise could set a fail grade or a rough cell, so the
      // full test runs. Not for a density that bounds itself: a hidden-mass
      // bound could split the cell too, and the split needs the children.
      const bool exact = affine_ && options_.rho >= kExactLeastRho && !eval.piecewise &&
                         !eval.warped() && !density_.Bounds() &&
                         density_.IsUniformOn(x * h, x * h + h, y * h, y * h + h);
      int flat = kNeverFails;
      if (exact) {
        ASSIGN_OR_RETURN(flat, FlatGrade(eval, depth, x, y, h));
      }
      if (!exact || flat <= grade_) {
        for (int c = 0; c < curve_.arity(); ++c) {
          const Curve::Child& ch = curve_.ChildOf(state, c);
          ASSIGN_OR_RETURN(children[c], Evaluate(depth + 1, x * g + ch.dx, y * g + ch.dy));
          error += std::fabs(ModelOverChild(eval, ch.dx, ch.dy, h) - children[c].mass);
        }
        error += EdgeError(eval, x * h, y * h, h);
        fail = FailGrade(error, eval.mass, base_, options_.rho);
        rough = IsRough(eval, error) && follow_steps;
        if (rough) fail = std::min(fail, RoughGrade(eval.mass, base_));
        if (!exact) {
          ASSIGN_OR_RETURN(flat, FlatGrade(eval, depth, x, y, h));
        }
      } else {
        fail = kNeverFails;
      }
      fail = std::min(fail, flat);
    }
    if (density_.Bounds() && !(fail <= grade_ && depth < options_.depth_cap)) find_hidden();
    // At the depth cap nothing can split the leaf, and a refinement never
    // examines it again.
    if (depth < options_.depth_cap) fail = std::min(fail, hidden_grade);
    if (fail <= grade_ && depth < options_.depth_cap) {
      NoteDepth(depth + 1, (x + 0.5) * h, (y + 0.5) * h);
      const uint64_t span = curve_.Span(depth + 1);
      for (int c = 0; c < curve_.arity(); ++c) {
        const Curve::Child& ch = curve_.ChildOf(state, c);
        RETURN_IF_ERROR(Refine(depth + 1, start + c * span, x * g + ch.dx, y * g + ch.dy, ch.state,
                               children[c], rough));
      }
      return absl::OkStatus();
    }
    RETURN_IF_ERROR(Grow());
    double mass = eval.mass;
    if (options_.estimator == AreaEstimator::kSquare) {
      ASSIGN_OR_RETURN(mass, CellMass(surface_, density_, AreaEstimator::kSquare, x * h, y * h, h));
    }
    starts_.push_back(start);
    masses_.push_back(ToFixed(mass));
    models_.push_back(eval.piecewise ? LeafModel::FromPiecewise(eval.values, g)
                                     : LeafModel::FromQuadratic(eval.values, eval.warp));
    errors_.push_back(static_cast<float>(error));
    info_.push_back(static_cast<uint8_t>(fail | (eval.piecewise ? kPiecewiseBit : 0) |
                                         (rough_parent ? kRoughParentBit : 0)));
    if (hidden > 0) NoteHidden(hidden, depth, x, y, h);
    return absl::OkStatus();
  }

  // The paper's flatness test, for leaves that carry a whole sample: the
  // grade at which the examined cell fails it.
  absl::StatusOr<int> FlatGrade(const CellEval& eval, int depth, uint64_t x, uint64_t y,
                                double h) {
    int flat = SamplesGrade(eval.mass, base_, kFlatnessFloor);
    // Beside a line where the area element blows up (a warp with power
    // above 1) the mapped probes spread like h^(1 + p), p < 0, and the test
    // would split down to the sample floors: many small leaves, each a
    // separate square the line's thin bands cut across, which loses the
    // stratification the warped curve gives (docs/ALGORITHM.md, "Singular
    // parameterisations"). The model error test governs those leaves.
    if (eval.warp[0].power > 1 || eval.warp[1].power > 1) flat = kNeverFails;
    if (flat <= grade_) {
      ASSIGN_OR_RETURN(const double spread, CellSpread(x * h, y * h, h));
      if (!(spread > options_.tolerance)) {
        flat = kNeverFails;
      } else if (depth >= options_.depth_cap) {
        ++report_.geometry_capped_leaves;
        RecordHit({DepthCapHit::Test::kGeometry, x * h, y * h, h, spread, options_.tolerance},
                  &report_.worst);
      }
    }
    return flat;
  }

  // Adds a leaf's hidden-mass bound to the sum and the places reported.
  void NoteHidden(double hidden, int depth, uint64_t x, uint64_t y, double h) {
    hidden_units_ = SaturatingAdd(hidden_units_, ToFixed(hidden));
    if (hidden > worst_hidden_) {
      worst_hidden_ = hidden;
      worst_hidden_cell_ = {x * h, y * h, h, depth, 0, x, y};
    }
    hidden_box_[0] = std::min(hidden_box_[0], x * h);
    hidden_box_[1] = std::max(hidden_box_[1], x * h + h);
    hidden_box_[2] = std::min(hidden_box_[2], y * h);
    hidden_box_[3] = std::max(hidden_box_[3], y * h + h);
  }

  uint64_t ToFixed(double mass) const {
    const double q = std::ldexp(mass / base_, kMassBits);
    return q >= 0x1p63 ? (uint64_t{1} << 63) : static_cast<uint64_t>(std::llround(q));
  }

  // Per-leaf masses for the triangle estimator (a), from the final leaves.
  absl::Status ComputeTriangleMasses() {
    const size_t n = starts_.size();
    auto centre = [&](size_t l) {
      const CurveTree::Cell cell =
          CellOfRange(curve_, starts_[l], l + 1 < n ? starts_[l + 1] : curve_.Span(0));
      return std::pair<double, double>{cell.u0 + cell.size / 2, cell.v0 + cell.size / 2};
    };
    if (n < 3) return absl::OkStatus();  // too few vertices for (a): keep the model's masses
    for (size_t l = 0; l < n; ++l) {
      // The end vertices use the nearest full triangle.
      const size_t mid = std::clamp<size_t>(l, 1, n - 2);
      const auto [u0, v0] = centre(mid - 1);
      const auto [u1, v1] = centre(mid);
      const auto [u2, v2] = centre(mid + 1);
      ASSIGN_OR_RETURN(const double mass, TriangleMass(surface_, density_, u0, v0, u1, v1, u2, v2));
      masses_[l] = ToFixed(mass);
    }
    return absl::OkStatus();
  }

  absl::Status BudgetError() const {
    // Say where the tree was growing deepest: usually a singularity.
    return absl::ResourceExhaustedError(absl::StrCat(
        LeafBudgetError(options_.max_leaves, stage2_ ? grade_ : -1).message(),
        absl::StrFormat(". The deepest split so far is at depth %d near (u,v) = (%.9g, %.9g)%s",
                        deepest_, deepest_u_, deepest_v_,
                        deepest_ >= 20 ? "; the surface may be singular there" : "")));
  }

  // Room for one more leaf, within the budget. Capacity grows by half and
  // never past the budget; PodArray grows without copying and its unwritten
  // tail takes no memory, so the peak is about the leaves' own bytes (docs/MEASURED.md).
  absl::Status Grow() {
    if (starts_.size() >= options_.max_leaves) return BudgetError();
    if (starts_.size() == starts_.capacity()) {
      Reserve(std::min<uint64_t>(options_.max_leaves,
                                 starts_.capacity() + starts_.capacity() / 2 + 1024));
    }
    return absl::OkStatus();
  }

  void Reserve(size_t n) {
    n = std::min<uint64_t>(n, options_.max_leaves);
    starts_.reserve(n);
    masses_.reserve(n);
    models_.reserve(n);
    errors_.reserve(n);
    info_.reserve(n);
  }

  // Asks the caller whether to go on, every BuildControl::kCheckInterval cells.
  absl::Status Checkpoint() {
    if ((!control_.check && !control_.charge) ||
        ++cells_since_check_ < BuildControl::kCheckInterval) {
      return absl::OkStatus();
    }
    cells_since_check_ = 0;
    if (control_.charge)
      RETURN_IF_ERROR(control_.charge(starts_.size() * CurveTree::kBytesPerLeaf));
    return control_.check ? control_.check() : absl::OkStatus();
  }

  void NoteDepth(int depth, double u, double v) {
    if (depth <= deepest_) return;
    deepest_ = depth;
    deepest_u_ = u;
    deepest_v_ = v;
  }

  const Surface& surface_;
  const Density& density_;
  const CurveTreeOptions& options_;
  const BuildControl& control_;
  uint64_t cells_since_check_ = 0;
  const Curve& curve_;
  const int order_;
  // Surface::IsAffine: a cell's quadratic model is exact where the density
  // is uniform (Density::IsUniformOn), and the error test's children are
  // evaluated there only for a split.
  const bool affine_;
  double base_ = 1;
  int grade_ = 0;
  bool stage2_ = false;  // past stage 1: the count shapes the tree
  int deepest_ = 0;
  double deepest_u_ = 0.5, deepest_v_ = 0.5;
  std::vector<uint64_t> stage1_starts_;
  double stage1_mass_ = 0;
  // Per stage-1 leaf, for densities that bound themselves: mass and
  // hidden-mass bound.
  std::vector<double> stage1_masses_, stage1_hidden_;
  // Stage 2: the leaves' hidden-mass bounds in mass units (saturating), the
  // largest one's cell and the box of the cells of those that hide any.
  uint64_t hidden_units_ = 0;
  double worst_hidden_ = 0;
  CurveTree::Cell worst_hidden_cell_{};
  double hidden_box_[4] = {INFINITY, -INFINITY, INFINITY, -INFINITY};  // u0, u1, v0, v1
  double stage1_area_ = 0;
  PodArray<uint64_t> starts_;
  PodArray<uint64_t> masses_;  // per leaf, fixed point
  PodArray<LeafModel> models_;
  PodArray<float> errors_;
  PodArray<uint8_t> info_;
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
    return absl::InvalidArgumentError(
        absl::StrFormat("depth cap must be in [0, %d] for the %s curve (0 = deepest), got %d",
                        curve.max_depth(), CurveName(options.curve), options.depth_cap));
  }
  if (!(options.rho > 0) || !std::isfinite(options.rho)) {
    return absl::InvalidArgumentError(absl::StrFormat("rho must be > 0, got %g", options.rho));
  }
  if (options.max_leaves == 0) return absl::InvalidArgumentError("max_leaves must be >= 1");
  if (options.depth_cap == 0) options.depth_cap = curve.max_depth();
  Vec3 lo{INFINITY, INFINITY, INFINITY}, hi{-INFINITY, -INFINITY, -INFINITY};
  double u = 0, v = 0;
  if (!WidenByGridPoints(surface, &lo, &hi, &u, &v)) return SurfaceNotFiniteError(u, v);
  const double diagonal = Diagonal(lo, hi);
  RETURN_IF_ERROR(CheckSize("the surface", diagonal));
  if (options.tolerance == 0) {
    if (!(diagonal > 0)) {
      return absl::InvalidArgumentError(
          "the surface maps the whole parameter box to one point; it has no area to sample");
    }
    options.tolerance = kAutomaticToleranceShare * diagonal;
  }
  return options;
}

}  // namespace

bool WidenByGridPoints(const Surface& surface, Vec3* lo, Vec3* hi, double* u, double* v) {
  bool finite = true;
  for (int i = 0; i <= kToleranceGrid; ++i) {
    for (int j = 0; j <= kToleranceGrid; ++j) {
      const double s = static_cast<double>(i) / kToleranceGrid;
      const double t = static_cast<double>(j) / kToleranceGrid;
      const Vec3 p = surface.Point(s, t);
      if (!IsFinite(p)) {
        if (finite) *u = s, *v = t;
        finite = false;
        continue;
      }
      *lo = {std::min(lo->x, p.x), std::min(lo->y, p.y), std::min(lo->z, p.z)};
      *hi = {std::max(hi->x, p.x), std::max(hi->y, p.y), std::max(hi->z, p.z)};
    }
  }
  return finite;
}

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
    return absl::InvalidArgumentError(
        absl::StrFormat("tree grade must be in [0, 62], got %d", grade));
  }
  ASSIGN_OR_RETURN(const CurveTreeOptions resolved, ResolveOptions(surface, options));
  auto tree = std::shared_ptr<CurveTree>(new CurveTree());
  tree->curve_ = &Curve::Get(resolved.curve);
  tree->options_ = resolved;
  tree->grade_ = grade;
  Builder builder(surface, density, tree->options_, control);
  RETURN_IF_ERROR(builder.BuildGeometric());
  RETURN_IF_ERROR(builder.RefineHiddenStage1());
  const double base = builder.stage1_mass();
  if (!(builder.stage1_area() > 0)) {
    return absl::InvalidArgumentError(
        "the surface has zero area (its area element vanishes on the whole parameter box, e.g. "
        "it is a curve or a point); there is nothing to sample");
  }
  RETURN_IF_ERROR(CheckMassIsFinite(base, "the surface"));
  if (!(base > 0)) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "the density integrates to %g over the surface; it must be positive somewhere (check "
        "the density, or add a floor)",
        base));
  }
  if (base < CurveTree::kSmallestMass) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "the density integrates to %g over the surface, too small to resolve (below %g, where "
        "its masses' unit leaves the normal doubles); scale it up: only its ratios matter",
        base, CurveTree::kSmallestMass));
  }
  tree->base_mass_ = base;
  tree->mass_unit_ = std::ldexp(base, -kMassBits);
  const std::vector<uint64_t>& starts = builder.stage1_starts();
  builder.StartStage2(base, grade, starts.size() * 2);
  const Curve& curve = *tree->curve_;
  for (size_t l = 0; l < starts.size(); ++l) {
    const uint64_t end = l + 1 < starts.size() ? starts[l + 1] : curve.Span(0);
    const Cell cell = CellOfRange(curve, starts[l], end);
    RETURN_IF_ERROR(builder.RefineCell(cell.depth, starts[l], cell.x, cell.y, cell.state, true));
  }
  tree->precision_ = builder.report();
  RETURN_IF_ERROR(builder.Finish(tree.get()));
  return std::shared_ptr<const CurveTree>(std::move(tree));
}

namespace {
constexpr absl::string_view kOverflowWords =
    "the density's values overflow double precision; scale it down (only its ratios matter)";
}  // namespace

absl::Status CurveTree::CheckMassIsFinite(double mass, absl::string_view where) {
  if (std::isfinite(mass)) return absl::OkStatus();
  return absl::InvalidArgumentError(
      absl::StrFormat("the density times the area element integrates to %g over %s: %s", mass,
                      where, kOverflowWords));
}

bool CurveTree::IsMassOverflow(const absl::Status& status) {
  return status.code() == absl::StatusCode::kInvalidArgument &&
         absl::StrContains(status.message(), kOverflowWords);
}

absl::StatusOr<std::shared_ptr<const CurveTree>> CurveTree::Refined(
    const Surface& surface, const Density& density, int grade, const BuildControl& control) const {
  if (grade < grade_ || grade > 62) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "cannot refine a grade-%d tree to grade %d; grades only grow, up to 62", grade_, grade));
  }
  auto tree = std::shared_ptr<CurveTree>(new CurveTree());
  tree->curve_ = curve_;
  tree->options_ = options_;
  tree->grade_ = grade;
  tree->base_mass_ = base_mass_;
  tree->mass_unit_ = mass_unit_;
  Builder builder(surface, density, tree->options_, control);
  builder.set_report(precision_);  // keeps the flatness hits of leaves at the cap
  builder.StartStage2(base_mass_, grade, leaf_count() + leaf_count() / 4);
  builder.set_hidden_units(hidden_units_);
  for (size_t l = 0; l < leaf_count(); ++l) {
    const Cell cell = LeafCell(l);
    if (leaf_fail_grade(l) <= grade && cell.depth < options_.depth_cap) {
      RETURN_IF_ERROR(builder.RefineCell(cell.depth, starts_[l], cell.x, cell.y, cell.state,
                                         leaf_rough_parent(l), true));
    } else {
      RETURN_IF_ERROR(builder.CopyLeaf(*this, l));
    }
  }
  tree->precision_ = builder.report();
  RETURN_IF_ERROR(builder.Finish(tree.get()));
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

size_t CurveTree::FirstLeafEndingAbove(double m, size_t lo) const {
  const double unit = mass_unit_;
  return static_cast<size_t>(std::upper_bound(mass_end_.begin() + lo, mass_end_.end(), m,
                                              [unit](double x, uint64_t end) {
                                                return x < static_cast<double>(end) * unit;
                                              }) -
                             mass_end_.begin());
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

void CurveTree::ComputeReport() {
  PrecisionReport& r = precision_;
  r.mass_capped_leaves = r.small_failing_leaves = r.singular_leaves = r.warped_leaves = 0;
  r.error_samples = r.unresolved_error_samples = 0;
  r.singular.clear();
  r.worst.erase(
      std::remove_if(r.worst.begin(), r.worst.end(),
                     [](const DepthCapHit& h) { return h.test == DepthCapHit::Test::kMass; }),
      r.worst.end());
  const double n = std::ldexp(1.0, grade_);
  for (size_t l = 0; l < starts_.size(); ++l) {
    const double error = errors_[l] / base_mass_ * n;
    r.error_samples += error;
    const bool piecewise = leaf_model_kind(l) == LeafModel::Kind::kPiecewise;
    const bool warped =
        !piecewise && (models_[l].warp[0].power != 1 || models_[l].warp[1].power != 1);
    if (piecewise) ++r.singular_leaves;
    if (warped) ++r.warped_leaves;
    const int fail = leaf_fail_grade(l);
    const double mass = mass_end(l) - mass_begin(l);
    const double allowance = options_.rho * kErrorShare * FourthRootN(n) * mass / base_mass_;
    const bool error_fails = error > allowance;
    if (fail <= grade_) {
      ++r.mass_capped_leaves;
      r.unresolved_error_samples += error;
      const Cell c = LeafCell(l);
      RecordHit({DepthCapHit::Test::kMass, c.u0, c.v0, c.size, error, allowance}, &r.worst);
    } else if (error_fails) {
      ++r.small_failing_leaves;
      r.unresolved_error_samples += error;
    }
    if (piecewise || warped) {
      const Cell c = LeafCell(l);
      DepthCapHit hit{DepthCapHit::Test::kSingular, c.u0, c.v0, c.size, 0, 0};
      auto pos = std::upper_bound(
          r.singular.begin(), r.singular.end(), hit,
          [](const DepthCapHit& a, const DepthCapHit& b) { return a.size < b.size; });
      r.singular.insert(pos, hit);
      if (r.singular.size() > PrecisionReport::kMaxReported) r.singular.pop_back();
    }
  }
}

}  // namespace sfc
