// The curve through a triangle mesh and the mass along it (docs/ALGORITHM.md
// steps 1-2, carried from the parameter square to a mesh).
//
// The curve. Triangles are visited in the order of recursive bisection by
// area (mesh/triangle_order.h), so consecutive
// triangles are close in space, and each triangle carries its own
// Sierpinski-type curve: its first split is at the midpoint of its longest
// edge, whose two ends are the curve's entry and exit (the exit is the end
// nearer the next triangle's centroid); every later split is newest-vertex
// bisection (Sewell 1972; Mitchell 1991): a cell (entry E, exit X, apex A)
// splits at M = (E + X) / 2 into (E, A, M) then (A, X, M). The curve stays
// continuous inside a triangle (the children meet at A), the children have
// equal areas, and all descendants fall into at most four similarity classes,
// so cells shrink evenly (diameter ~ 2^(-depth/2)). Each split is an affine
// map of barycentric coordinates: no lengths are compared below the root, and
// a sample's descent costs a few flops per level. We chose this over a walk
// across neighbouring triangles because the bisection order needs no
// connectivity (non-manifold and disconnected meshes work alike), and over
// the mesh's UV atlas (Quinn, Langbein, Martin 2007) because most files have
// none and atlases have seams.
//
// Adaptivity. A triangle is a leaf unless its density is not constant. Each
// cell then has two estimates of its mass: the three-edge-midpoint rule
// (exact for quadratic densities), which becomes the leaf's mass, and the
// integral of the linear model through its three corner values, which is
// what samples inside the leaf follow (MeshCurveTree::Descend). A cell splits
// while the two differ by more than `tolerance` samples of a set of
// N = 2^grade (|difference| / S_M * N). The leaf masses carry only the
// midpoint rule's O(h^3) error, so a run of whole leaves hides no model
// error; the model's error shows only inside leaves a region cuts, at most
// `tolerance` samples each, below the jittered set's own discrepancy (about
// N^(1/4) samples; docs/ALGORITHM.md "A tree sized by the surface"). The model
// error of a cell of size h holding n samples is ~ n h^2 ~ N h^4, so for a
// smooth density the leaf count grows like N^(1/2), not N. Uniform density
// never splits (masses are exact areas): a mesh of T triangles is a tree of
// T leaves for every N, and a small triangle is never split before a large
// one of the same density.
//
// Thread-safety: thread-safe; immutable after Build() but for the bounding
// boxes of RanksMeetingBox, which its first call builds (once, for all).
#ifndef SFCSAMPLER_MESH_MESH_CURVE_TREE_H_
#define SFCSAMPLER_MESH_MESH_CURVE_TREE_H_

#include <array>
#include <cstdint>
#include <memory>
#include <mutex>
#include <utility>
#include <vector>

#include "absl/status/statusor.h"
#include "core/types/vec3.h"
#include "mesh/mesh_density.h"
#include "mesh/mesh_surface.h"

namespace sfc {

struct MeshTreeOptions {
  // The sample count the tree must serve; the error test uses 2^grade with
  // grade = ceil(log2(count)), so every count of one grade shares a tree.
  // REQUIRES: count >= 1.
  uint64_t count = 1'000'000;
  // The split test's bound on a leaf's model error, in samples (> 0);
  // smaller splits more.
  double tolerance = 0.25;
  // Bisection levels below a mesh triangle, 0..56. Cells the cap stops are
  // counted in Stats::capped_leaves.
  int max_depth = 40;
  // Parallel parts, >= 1, of the triangles' order (mesh/triangle_order.h:
  // the top levels' splits, up to the next power of two, at most 64) and of
  // the ranks' roles and boxes (at most 8), run on the process's worker pool
  // (base/worker_pool.h); the same tree for any count.
  int threads = 1;
  // RESOURCE_EXHAUSTED past this many leaves (32 bytes each for non-uniform
  // densities, 24 for uniform).
  uint64_t max_leaves = uint64_t{1} << 25;
};

class MeshCurveTree {
 public:
  // Errors: INVALID_ARGUMENT for bad options, a density that needs weights on
  // a mesh without them, or a density that is negative or not finite
  // somewhere (the message gives the point); RESOURCE_EXHAUSTED past
  // max_leaves; FAILED_PRECONDITION when the density is zero on the whole mesh.
  // A density that needs curvature requires surface->has_curvature().
  static absl::StatusOr<std::shared_ptr<const MeshCurveTree>> Build(
      std::shared_ptr<const MeshSurface> surface, std::shared_ptr<const MeshDensity> density,
      const MeshTreeOptions& options);

  // A leaf cell: corners in their curve roles (entry, exit, apex) as
  // barycentric coordinates of its mesh triangle, the density model's values
  // there, and where the cell lies on its triangle's curve (area fractions).
  struct Cell {
    uint32_t triangle = 0;
    uint32_t rank = 0;  // the triangle's position in curve order
    std::array<std::array<double, 3>, 3> corner{};
    std::array<double, 3> density{1, 1, 1};
    bool uniform = true;  // model constant inside the cell
    double area_begin = 0, area_size = 1;
  };

  struct Stats {
    uint64_t leaves = 0;
    uint64_t triangles = 0;        // triangles on the curve (non-degenerate)
    uint64_t split_triangles = 0;  // triangles with more than one leaf
    int max_depth = 0;             // deepest leaf below its triangle
    uint64_t capped_leaves = 0;    // leaves the depth cap stopped
    uint64_t density_evaluations = 0;
    uint64_t bytes = 0;            // memory held by the tree's arrays
    int grade = 0;
  };

  const MeshSurface& surface() const { return *surface_; }
  const std::shared_ptr<const MeshSurface>& surface_ptr() const { return surface_; }
  const MeshDensity& density() const { return *density_; }
  const Stats& stats() const { return stats_; }

  size_t leaf_count() const { return mass_ends_.size(); }
  double total_mass() const { return mass_ends_.back(); }
  // Running masses S_l (leaf l holds [S_{l-1}, S_l)).
  const std::vector<double>& mass_ends() const { return mass_ends_; }
  double mass_begin(size_t l) const { return l == 0 ? 0.0 : mass_ends_[l - 1]; }
  Cell LeafCell(size_t l) const;

  size_t triangle_count() const { return rank_triangle_.size(); }  // on the curve
  uint32_t triangle_at_rank(size_t r) const { return rank_triangle_[r]; }
  // Leaves of rank r are [first_leaf(r), first_leaf(r + 1)).
  size_t first_leaf(size_t r) const { return rank_first_leaf_[r]; }

  // Appends to `runs` the maximal rank ranges [a, b), in curve order, whose
  // triangles' bounding boxes (of their vertices: exact for flat triangles)
  // may meet the closed box [lo, hi]. Triangles outside are skipped whole.
  // The first call builds the boxes (requests without a region, most of them,
  // never pay for them).
  void RanksMeetingBox(const Vec3& lo, const Vec3& hi,
                       std::vector<std::pair<size_t, size_t>>* runs) const;

  // Follows the fraction t in [0, 1) of a leaf's mass down the leaf's own
  // curve for 52 more levels (docs/ALGORITHM.md "Inside a leaf, follow the
  // model"): at each level the two children share the mass by the exact
  // integrals of the cell's linear model, and t moves into the child that
  // holds it. Gives the barycentric coordinates of the final cell's centroid
  // and its position along the triangle's curve (area fraction).
  static void Descend(const Cell& cell, double t, std::array<double, 3>* bary,
                      double* area_position);
  // Descend for n samples at once, bit for bit the same results: the 52
  // levels of the uniform cells run interleaved across the samples, which
  // overlaps their chains of dependent steps. cells[i] is sample i's cell.
  static void DescendMany(size_t n, const Cell* const* cells, const double* t,
                          std::array<double, 3>* bary, double* area_position);

  // The bisection levels below a leaf that a sample's place holds: all the
  // bits of its fraction (Descend), 2^-26 of the leaf's size.
  static constexpr int kLevels = 52;
  // The kLevels child choices (first level highest) of the sub-cell holding
  // the point (a, b) of a cell's frame, entry (0, 0), exit (1, 0), apex
  // (0, 1): where the geometry alone puts it, whatever the cell's density.
  static uint64_t PathOf(double a, double b);
  // The centroid of the sub-cell `path` (PathOf's choices) of `cell`, by the
  // geometry alone: barycentrics in its triangle and the area position along
  // the triangle's curve; bit for bit Descend's for a uniform cell at the
  // fraction path 2^-kLevels. n at once, interleaved as DescendMany.
  static void DescendPaths(size_t n, const Cell* const* cells, const uint64_t* paths,
                           std::array<double, 3>* bary, double* area_position);

 private:
  struct Box {
    Vec3 lo, hi;
  };
  MeshCurveTree() = default;
  Box TriangleBox(size_t rank) const;  // of its vertices
  // Ranks [begin, end): their entry and exit corners (rank_roles_). Disjoint
  // ranges may run at once.
  void PlaceRanks(size_t begin, size_t end, const std::vector<Vec3>& centroid);
  // boxes_: its leaves (box_parts_ parts of whole leaves at once), then its
  // inner nodes. Run once, by RanksMeetingBox.
  void BuildBoxes() const;
  void CollectRuns(size_t node, size_t node_lo, size_t node_hi, const Vec3& lo, const Vec3& hi,
                   std::vector<std::pair<size_t, size_t>>* runs) const;

  std::shared_ptr<const MeshSurface> surface_;
  std::shared_ptr<const MeshDensity> density_;
  // Per rank (curve order of triangles).
  std::vector<uint32_t> rank_triangle_;
  std::vector<uint8_t> rank_roles_;         // entry corner * 3 + exit corner
  std::vector<uint32_t> rank_first_leaf_;   // size ranks + 1
  // Per leaf.
  std::vector<uint32_t> leaf_rank_;
  std::vector<uint64_t> leaf_path_;         // child choices, first level highest
  std::vector<uint8_t> leaf_depth_;
  std::vector<std::array<double, 3>> leaf_density_;  // empty for uniform density
  std::vector<double> mass_ends_;
  // Bounding boxes over runs of ranks: a complete binary tree, node 1 the
  // root, whose leaves hold kRanksPerBox ranks each; built by the first
  // RanksMeetingBox.
  mutable std::once_flag boxes_once_;
  mutable std::vector<Box> boxes_;
  size_t box_leaves_ = 0;
  size_t box_parts_ = 1;
  Stats stats_;
};

}  // namespace sfc

#endif  // SFCSAMPLER_MESH_MESH_CURVE_TREE_H_
