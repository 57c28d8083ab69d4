// The adaptive curve tree (paper Fig. 2, PopulateCurveTree) with the masses
// along the curve (Fig. 1 lines 4-6), stored as its leaves in curve order.
//
// A tree is built in two stages, both deterministic:
//  1. The paper's geometric test: a cell is split while the largest distance
//     from f(centre) to f at its 4 corners and 4 edge midpoints exceeds the
//     tolerance a, and its depth is below the cap r (AssessSubdivision).
//  2. The sample-mass test of ALGORITHM.md, graded: a tree of grade g is fine
//     enough for up to 2^g samples, i.e. no leaf below the cap carries more
//     than rho * S_base / 2^g of mass, where S_base is the total mass of the
//     stage-1 tree (fixed, so decisions never depend on later refinement).
//     Children made by this test inherit their parent's geometric pass: a cell
//     flat to a is re-split only for mass.
// The tree of grade g is by definition stage 1 followed by the refinement
// passes for grades 1..g; Refined() runs the missing passes on a coarser tree,
// so a cached tree refined from g to g' is bit-identical to one built for g'.
//
// Leaf layout: 16 bytes per leaf, the 64-bit curve index where the leaf starts
// (its cell, depth and orientation follow from it and the next leaf's start)
// and the running mass S_l at its end.
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
#include "core/area_estimator.h"
#include "core/curve.h"
#include "core/density.h"
#include "core/surface.h"

namespace sfc {

struct CurveTreeOptions {
  CurveType curve = CurveType::kHilbert;
  AreaEstimator estimator = AreaEstimator::kFirstFundamentalForm;
  // The paper's a, in surface units; 0 means automatic: 1% of the diagonal of
  // the surface's bounding box (measured on a 17 x 17 parameter grid).
  double tolerance = 0;
  // The paper's r; 0 means the curve's deepest level (31 Hilbert, 20 3x3).
  int depth_cap = 0;
  // Largest mass a leaf may carry, in samples' worth (ALGORITHM.md); > 0.
  double rho = 1.0;
  // Budget: building or refining past this many leaves is RESOURCE_EXHAUSTED.
  uint64_t max_leaves = uint64_t{1} << 24;
};

// Where the depth cap stopped a split that a test still wanted (paper Sect. 5.3).
struct DepthCapHit {
  enum class Test { kGeometry, kMass };
  Test test = Test::kGeometry;
  double u0 = 0, v0 = 0, size = 0;  // the leaf's parameter cell
  double measured = 0;              // distance (geometry) or mass (mass test)
  double limit = 0;                 // the tolerance a, or the grade's mass limit
};

// Lets the caller stop a build or refinement that is no longer wanted (its
// client went away, its deadline passed, the server is shutting down).
// `check` is called at least every kCheckInterval cell evaluations; a non-OK
// status it returns aborts the build, which then returns that status.
struct BuildControl {
  std::function<absl::Status()> check;  // empty: never stop
  static constexpr uint64_t kCheckInterval = 4096;
};

struct PrecisionReport {
  uint64_t geometry_capped_leaves = 0;
  uint64_t mass_capped_leaves = 0;
  std::vector<DepthCapHit> worst;  // at most kMaxReported, largest measured/limit first
  static constexpr int kMaxReported = 8;
};

class CurveTree {
 public:
  // Builds the tree of `grade` (0 <= grade <= 62). Errors: INVALID_ARGUMENT
  // for bad options, a surface that is not finite, a negative density or a
  // density that integrates to zero; RESOURCE_EXHAUSTED past max_leaves.
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
  // Running masses: mass_begin(l) = S_{l-1}, mass_end(l) = S_l.
  double mass_begin(size_t l) const { return l == 0 ? 0.0 : mass_end_[l - 1]; }
  double mass_end(size_t l) const { return mass_end_[l]; }
  const std::vector<double>& mass_ends() const { return mass_end_; }
  double total_mass() const { return mass_end_.back(); }
  double base_mass() const { return base_mass_; }

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

  const PrecisionReport& precision() const { return precision_; }
  int min_depth() const { return min_depth_; }
  int max_depth() const { return max_depth_; }
  // Bytes held by the leaf arrays.
  size_t bytes() const { return starts_.capacity() * sizeof(uint64_t) + mass_end_.capacity() * sizeof(double); }
  static constexpr size_t kBytesPerLeaf = sizeof(uint64_t) + sizeof(double);

 private:
  class Builder;
  CurveTree() = default;
  // The cell covering curve indices [start, end). REQUIRES: a cell's range.
  static Cell CellOfRange(const Curve& curve, uint64_t start, uint64_t end);
  void ComputeDepthRange();

  const Curve* curve_ = nullptr;
  CurveTreeOptions options_;
  int grade_ = 0;
  double base_mass_ = 0;
  std::vector<uint64_t> starts_;
  std::vector<double> mass_end_;
  PrecisionReport precision_;
  int min_depth_ = 0, max_depth_ = 0;
};

}  // namespace sfc

#endif  // SFCSAMPLER_CORE_CURVE_TREE_H_
