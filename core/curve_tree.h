// The adaptive curve tree (paper Fig. 2, PopulateCurveTree) with the masses
// along the curve (Fig. 1 lines 4-6), stored as its leaves in curve order,
// each with a local model of the mass density (core/leaf_model.h).
//
// A tree is built in two stages, both deterministic:
//  1. The paper's geometric test down to a base depth (6 for Hilbert, 4 for
//     the 3x3 curves): a cell is split while the largest distance from
//     f(centre) to f at its 4 corners and 4 edge midpoints exceeds the
//     tolerance a (AssessSubdivision). For a density that bounds itself
//     (Density::Bounds) a leaf that may hide mass no probe saw is then split
//     (kStage1HiddenShare). S_base is the total mass of these leaves (fixed,
//     so decisions never depend on later refinement).
//  2. Graded refinement: a tree of grade g serves up to N = 2^g samples. With
//     mu = mass / S_base a leaf's share, a leaf splits (below the cap r) when
//      - its model error e, the sum over its children of |its model's
//        integral over the child - the child's own mass estimate|, is too
//        large:  e / S_base * N > rho * kErrorShare * N^(1/4) * mu, while it
//        carries at least max(kMinSamples, kErrorFloor * N^(1/2)) samples; or
//      - it fails the paper's flatness test while it carries at least
//        max(kMinSamples, kFlatnessFloor * N^(1/2)) samples; or
//      - its hidden-mass bound (kHiddenFactor) is worth kHiddenFloor samples.
//     The error allowance is proportional to the leaf's share of the mass, so
//     the error summed over any run of examined leaves stays below rho *
//     kErrorShare * N^(1/4) samples: a fraction of the jittered set's own
//     discrepancy. The floors bound the tree: at most ~N / floor leaves are
//     examined, so leaves grow like N^(1/2) at worst (smooth surfaces: much
//     slower), and a singular line (where a smooth model's relative error
//     never shrinks) ends at leaves of a few samples, reported in precision().
//     On an affine surface, in a cell where the density is uniform
//     (Surface::IsAffine, Density::IsUniformOn) and does not bound itself,
//     the model is exact: at rho >= 1 the error is taken as 0 (the full
//     test's rounding noise could fail it only at a much smaller rho) and
//     the children are evaluated only when the flatness test splits the
//     leaf; the same tree as the full test's.
//     Every condition only tightens as N grows, so each leaf stores the
//     smallest grade at which it must be examined again ("fail grade"), and a
//     coarser tree refines exactly those leaves.
// The tree of grade g is by definition stage 1 followed by stage 2 at grade
// g; Refined() re-runs stage 2 from the leaves whose fail grade is <= the new
// grade, so a cached tree refined from g to g' is bit-identical to one built
// for g'.
//
// Mass estimates: the leaf's mass is its model's integral. The quadratic model
// (3 x 3 Gauss nodes) never evaluates on a cell edge. Where the area element
// blows up (it is not finite at a node, or the area of the mapped
// sub-squares' triangles exceeds the quadrature by kSingularExcess, which a
// smooth patch never does: inscribed triangles have less area), the leaf uses
// the piecewise model of the mapped triangles, which converges on singular
// lines (paper Sect. 5.3). Such leaves are counted and located in
// precision().
//
// Leaf layout: 73 bytes per leaf: the 64-bit curve index where the leaf
// starts (its cell, depth and orientation follow from it and the next leaf's
// start), the running mass S_l at its end in fixed point (units of
// S_base / 2^56, so a leaf's mass is an exact difference and refinement
// reproduces a fresh build bit for bit), the model (9 floats and its two
// power laws), its error
// estimate (a float) and one byte holding the model kind and the fail grade.
//
// Thread-safety: a built CurveTree is immutable and shared as
// std::shared_ptr<const CurveTree>; all const methods are thread-safe.
#ifndef SFCSAMPLER_CORE_CURVE_TREE_H_
#define SFCSAMPLER_CORE_CURVE_TREE_H_

#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "base/pod_array.h"
#include "core/area_estimator.h"
#include "core/curve.h"
#include "core/density.h"
#include "core/leaf_model.h"
#include "core/surface.h"
#include "core/types/tree_options.h"

namespace sfc {

// The automatic tolerance a (CurveTreeOptions::tolerance = 0) is this share
// of the diagonal of the box of the surface's points on the grid of
// kToleranceGrid x kToleranceGrid intervals of its unit square. A CAD model
// takes one for all its faces, from the box of all of theirs.
inline constexpr double kAutomaticToleranceShare = 0.01;
inline constexpr int kToleranceGrid = 16;
// Widens [*lo, *hi] to the surface's finite points on that grid; returns
// false, with the (u, v) of the first point that is not finite in *u, *v,
// when one is not (the rest of the grid is still taken).
bool WidenByGridPoints(const Surface& surface, Vec3* lo, Vec3* hi, double* u, double* v);

// Where the depth cap stopped a split that a test still wanted (paper Sect. 5.3).
struct DepthCapHit {
  // kGeometry / kMass: the depth cap stopped the flatness / error test.
  // kSingular: a leaf where the area element blows up (measured = limit = 0).
  enum class Test { kGeometry, kMass, kSingular };
  Test test = Test::kGeometry;
  double u0 = 0, v0 = 0, size = 0;  // the leaf's parameter cell
  double measured = 0;              // distance (geometry) or model error in samples (kMass)
  double limit = 0;                 // the tolerance a, or the leaf's error allowance in samples
};

// Lets the caller stop a build or refinement that is no longer wanted (its
// client went away, its deadline passed, the server is shutting down).
// `check` is called at least every kCheckInterval cell evaluations; a non-OK
// status it returns aborts the build, which then returns that status.
struct BuildControl {
  std::function<absl::Status()> check;  // empty: never stop
  // Told, at the same moments, the bytes of leaves the build holds so far
  // (leaves x kBytesPerLeaf), so a shared memory budget can count builds in
  // progress; a non-OK status aborts the build likewise. Empty: not told.
  std::function<absl::Status(uint64_t bytes)> charge;
  // False: a tree whose leaves may hide more than CurveTree::kHiddenShare of
  // its mass is returned anyway (precision().hidden_share says how much), for
  // a coarse tree that only measures a part's mass before the refinement that
  // checks it (a CAD model's faces, cad/model_sampler.h).
  bool refuse_hidden = true;
  static constexpr uint64_t kCheckInterval = 4096;
};

struct PrecisionReport {
  uint64_t geometry_capped_leaves = 0;
  uint64_t mass_capped_leaves = 0;  // the depth cap stopped the error test
  // Leaves whose error test failed but that carry fewer than kMinSamples
  // samples, so they were kept (a singular line ends this way).
  uint64_t small_failing_leaves = 0;
  // Leaves with the piecewise model: the area element is singular there and
  // no edge power law fits it.
  uint64_t singular_leaves = 0;
  // Leaves whose quadratic model is warped by a power law toward a singular
  // edge (LeafModel::warp): the area element blows up or vanishes on it.
  uint64_t warped_leaves = 0;
  // Precision reached: the estimated model error summed over all leaves, in
  // samples of the grade's N (each leaf's e / S_base * 2^grade).
  double error_samples = 0;
  // ... and summed over the leaves the tests still wanted to split.
  double unresolved_error_samples = 0;
  // The hidden-mass bound summed over the leaves, as a share of the total
  // mass (0 for densities that do not bound themselves).
  double hidden_share = 0;
  std::vector<DepthCapHit> worst;     // at most kMaxReported, largest measured/limit first
  // At most kMaxReported singular leaves (piecewise or warped), the smallest first.
  std::vector<DepthCapHit> singular;
  static constexpr int kMaxReported = 8;
};

class CurveTree {
 public:
  // Builds the tree of `grade` (0 <= grade <= 62). Errors: INVALID_ARGUMENT
  // for bad options, a surface that is not finite, a negative density, a
  // density that integrates to zero, or leaves that may hide more than
  // kHiddenShare of the mass (unless control.refuse_hidden is false);
  // RESOURCE_EXHAUSTED past max_leaves.
  static absl::StatusOr<std::shared_ptr<const CurveTree>> Build(const Surface& surface,
                                                                const Density& density,
                                                                const CurveTreeOptions& options,
                                                                int grade,
                                                                const BuildControl& control = {});

  // The grade-`grade` tree made by refining this one: only the leaves that
  // fail the finer mass test are evaluated. REQUIRES: the surface and density
  // this tree was built from; grade >= this->grade().
  absl::StatusOr<std::shared_ptr<const CurveTree>> Refined(const Surface& surface,
                                                           const Density& density,
                                                           int grade,
                                                           const BuildControl& control = {}) const;

  // The smallest grade fine enough for `count` samples: ceil(log2(count)).
  static int GradeFor(uint64_t count);

  // The error test's constants (file comment).
  static constexpr double kErrorShare = 0.25;
  // A leaf is examined by the error test only while it carries at least
  // max(kMinSamples, kErrorFloor N^(1/2)) samples, by the flatness test only
  // while it carries max(kMinSamples, kFlatnessFloor N^(1/2)).
  static constexpr double kMinSamples = 0.125;
  static constexpr double kErrorFloor = 1.0 / 64;
  static constexpr double kErrorFloorPower = 0.5;
  static constexpr double kFlatnessFloor = 1.0 / 16;
  static constexpr double kSingularExcess = 1.02;
  // A rough leaf (its quadratic misses more than rho kRoughShare of its mass, or
  // it fell back to the piecewise model) and its children are examined while
  // they carry at least kRoughFloor samples, a floor that does not grow with
  // N: steps, creases at zeros and singular lines at any position get leaves
  // small enough that the error along them falls like N^(-1/2)
  // (docs/ALGORITHM.md, "Features inside a leaf").
  static constexpr double kRoughShare = 0.01;
  static constexpr double kRoughFloor = 1.0 / 2048;
  // The least total mass a density may have over a surface, a mesh or a
  // model, 2^-966: below it the tree's mass unit (2^-56 of the total) and
  // a mesh's small leaves' masses leave the normal doubles, and samples
  // coincide (docs/ALGORITHM.md, "Tiny densities").
  static constexpr double kSmallestMass = 0x1p-966;
  // The refusal of a density whose total `mass` over `where` ("the surface",
  // "mesh 'NAME'", ...) overflows double precision (inf or nan), where the
  // tree would put every sample on one point (docs/ALGORITHM.md, "Huge
  // densities"); OK for any other mass. Surfaces, meshes and CAD models all
  // refuse with this one message.
  static absl::Status CheckMassIsFinite(double mass, absl::string_view where);
  // Whether `status` is CheckMassIsFinite's refusal (a CAD face whose mass
  // overflows is refused, never skipped as one with nothing to sample).
  static bool IsMassOverflow(const absl::Status& status);
  // The edge probe (EdgeError): a gap of kEdgeJump of the largest node value
  // between m and the model at a corner or edge midpoint counts, over a band
  // of kEdgeBand of the cell.
  static constexpr double kEdgeJump = 0.05;
  static constexpr double kEdgeBand = 1.0 / 16;
  // The hidden-mass check (docs/ALGORITHM.md, "Features narrower than the
  // probes"), for densities that bound themselves (Density::Bounds). A part
  // of a leaf may hide mass where the density's interval upper bound there
  // exceeds kHiddenFactor times the largest density the leaf's Gauss nodes
  // saw and a probe inside the narrowed part confirms it; the leaf's hidden
  // mass is the sum of those parts' bounds times their share of the leaf's
  // area.
  static constexpr double kHiddenFactor = 8;
  // Stage 1 splits a leaf while its bound exceeds kStage1HiddenShare of the
  // stage's mass, within kStage1HiddenLeaves leaves added; stage 2 examines
  // and splits one while its bound is worth kHiddenFloor samples (the rough
  // floor: a hidden feature is followed as far as a seen one).
  static constexpr double kStage1HiddenShare = 1.0 / 8192;
  static constexpr uint64_t kStage1HiddenLeaves = uint64_t{1} << 17;
  static constexpr double kHiddenFloor = kRoughFloor;
  // A tree whose leaves' bounds sum to more than kHiddenShare of its mass is
  // refused (INVALID_ARGUMENT, saying where).
  static constexpr double kHiddenShare = 1.0 / 1024;

  const Curve& curve() const { return *curve_; }
  // The options with tolerance and depth cap resolved to the values used.
  const CurveTreeOptions& options() const { return options_; }
  int grade() const { return grade_; }

  size_t leaf_count() const { return starts_.size(); }
  uint64_t leaf_start(size_t l) const { return starts_[l]; }
  uint64_t leaf_end(size_t l) const {
    return l + 1 < starts_.size() ? starts_[l + 1] : curve_->Span(0);
  }
  int leaf_depth(size_t l) const { return curve_->DepthOfSpan(leaf_end(l) - leaf_start(l)); }
  // Running masses: mass_begin(l) = S_{l-1}, mass_end(l) = S_l, both
  // non-decreasing in l.
  double mass_begin(size_t l) const { return l == 0 ? 0.0 : mass_end(l - 1); }
  double mass_end(size_t l) const { return static_cast<double>(mass_end_[l]) * mass_unit_; }
  double total_mass() const { return mass_end(mass_end_.size() - 1); }
  double base_mass() const { return base_mass_; }
  // The first leaf l with mass_end(l) > m (leaf_count() if none), searching
  // [lo, leaf_count()).
  size_t FirstLeafEndingAbove(double m, size_t lo = 0) const;
  // Its leaf's estimated model error (mass units).
  double leaf_error(size_t l) const { return errors_[l]; }

  // The leaf's parameter cell [u0, u0+size) x [v0, v0+size), its position
  // (x, y) among the g^depth x g^depth cells of its depth, and orientation.
  struct Cell {
    double u0, v0, size;
    int depth;
    int state;
    uint64_t x, y;
  };
  Cell LeafCell(size_t l) const;
  // Index of the leaf containing curve index `index`.
  size_t LeafAt(uint64_t index) const;

  // The leaf's density model and its kind, in the leaf's unit coordinates.
  const LeafModel& leaf_model(size_t l) const { return models_[l]; }
  LeafModel::Kind leaf_model_kind(size_t l) const {
    return (info_[l] & kPiecewiseBit) ? LeafModel::Kind::kPiecewise : LeafModel::Kind::kQuadratic;
  }
  // The smallest grade at which the leaf fails the error test (63: never).
  int leaf_fail_grade(size_t l) const { return info_[l] & kFailGradeMask; }
  // Whether the leaf's parent failed the rough test (kRoughShare), so the
  // leaf is examined down to kRoughFloor.
  bool leaf_rough_parent(size_t l) const { return info_[l] & kRoughParentBit; }

  const PrecisionReport& precision() const { return precision_; }
  int min_depth() const { return min_depth_; }
  int max_depth() const { return max_depth_; }
  // Bytes held by the leaf arrays.
  size_t bytes() const {
    return starts_.capacity() * sizeof(uint64_t) + mass_end_.capacity() * sizeof(uint64_t) +
           models_.capacity() * sizeof(LeafModel) + errors_.capacity() * sizeof(float) +
           info_.capacity();
  }
  static constexpr size_t kBytesPerLeaf = sizeof(uint64_t) + sizeof(uint64_t) + sizeof(LeafModel) +
                                          sizeof(float) + sizeof(uint8_t);

 private:
  class Builder;
  CurveTree() = default;
  // The cell covering curve indices [start, end). REQUIRES: a cell's range.
  static Cell CellOfRange(const Curve& curve, uint64_t start, uint64_t end);
  void ComputeDepthRange();
  void ComputeReport();

  const Curve* curve_ = nullptr;
  CurveTreeOptions options_;
  int grade_ = 0;
  double base_mass_ = 0;
  static constexpr uint8_t kFailGradeMask = 63;
  static constexpr uint8_t kPiecewiseBit = 64;
  static constexpr uint8_t kRoughParentBit = 128;

  // PodArray, not std::vector: growing them moves no bytes (base/pod_array.h).
  PodArray<uint64_t> starts_;
  PodArray<uint64_t> mass_end_;  // fixed point, units of mass_unit_
  double mass_unit_ = 0;            // base_mass_ / 2^56
  // The leaves' hidden-mass bounds summed in the same units (saturating), so
  // a refined tree's sum is a fresh build's to the bit.
  uint64_t hidden_units_ = 0;
  PodArray<LeafModel> models_;
  PodArray<float> errors_;
  PodArray<uint8_t> info_;  // fail grade | kPiecewiseBit | kRoughParentBit
  PrecisionReport precision_;
  int min_depth_ = 0, max_depth_ = 0;
};

}  // namespace sfc

#endif  // SFCSAMPLER_CORE_CURVE_TREE_H_
