// Internal to cad/: a TopoDS_Face as our Surface (FaceSurface) and its trim
// (FaceTrim). The only header of the library that includes OpenCASCADE's;
// included by cad/*.cc only.
//
// Thread-safety: the kernel's adaptors keep mutable caches (GeomAdaptor's
// B-spline span cache, the classifier's work data), so one adaptor must not
// be used by two threads at once. Each object here keeps a pool of adaptors:
// a call leases one (creating it if all are busy) and returns it, so const
// methods are safe from any number of threads and each thread reuses warm
// adaptors. The TopoDS_Face and its geometry are only read.
#ifndef SFCSAMPLER_CAD_INTERNAL_OCC_FACE_H_
#define SFCSAMPLER_CAD_INTERNAL_OCC_FACE_H_

#include <Adaptor2d_Curve2d.hxx>
#include <BRepAdaptor_Surface.hxx>
#include <BRepTopAdaptor_FClass2d.hxx>
#include <Geom2d_Curve.hxx>
#include <Geom_BSplineSurface.hxx>
#include <TopoDS_Face.hxx>
#include <atomic>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <vector>

#include "absl/base/thread_annotations.h"
#include "absl/synchronization/mutex.h"
#include "cad/internal/closed_form.h"
#include "cad/internal/line_circle_trim.h"
#include "cad/internal/span_hull.h"
#include "cad/model.h"
#include "core/surface.h"

namespace sfc::cad {

// A pool of objects that are not thread-safe, handed out one per caller.
template <typename T>
class LeasePool {
 public:
  explicit LeasePool(std::function<std::unique_ptr<T>()> make) : make_(std::move(make)) {}

  class Lease {
   public:
    Lease(LeasePool* pool, std::unique_ptr<T> item) : pool_(pool), item_(std::move(item)) {}
    ~Lease() { pool_->Return(std::move(item_)); }
    Lease(const Lease&) = delete;
    Lease& operator=(const Lease&) = delete;
    T& operator*() const { return *item_; }
    T* operator->() const { return item_.get(); }

   private:
    LeasePool* pool_;
    std::unique_ptr<T> item_;
  };

  // Thread-safe. The lease returns the object to the pool when it goes.
  Lease Take() ABSL_LOCKS_EXCLUDED(mu_) {
    LeasePool* self = this;
    {
      absl::MutexLock lock(&mu_);
      if (!free_.empty()) {
        std::unique_ptr<T> item = std::move(free_.back());
        free_.pop_back();
        return Lease(self, std::move(item));
      }
    }
    return Lease(self, make_());
  }

 private:
  void Return(std::unique_ptr<T> item) ABSL_LOCKS_EXCLUDED(mu_) {
    absl::MutexLock lock(&mu_);
    free_.push_back(std::move(item));
  }

  const std::function<std::unique_ptr<T>()> make_;
  absl::Mutex mu_;
  std::vector<std::unique_ptr<T>> free_ ABSL_GUARDED_BY(mu_);
};

// The linear map between a face's native (U, V) and the unit square (s, t):
// U = u0 + s (u1 - u0), or u1 - s (u1 - u0) for a reversed face; V likewise
// without reversal.
struct UnitSquareMap {
  ParameterBox box;
  bool reversed = false;

  double U(double s) const {
    return reversed ? box.u1 - s * (box.u1 - box.u0) : box.u0 + s * (box.u1 - box.u0);
  }
  double V(double t) const { return box.v0 + t * (box.v1 - box.v0); }
  double S(double u) const {
    return reversed ? (box.u1 - u) / (box.u1 - box.u0) : (u - box.u0) / (box.u1 - box.u0);
  }
  double T(double v) const { return (v - box.v0) / (box.v1 - box.v0); }
  // dU/ds and dV/dt.
  double DuDs() const { return reversed ? -(box.u1 - box.u0) : box.u1 - box.u0; }
  double DvDt() const { return box.v1 - box.v0; }
};

// The face as f : [0,1]^2 -> R^3, through BRepAdaptor_Surface (the face's
// location applied). Jet gives the kernel's exact derivatives (D1, D2) times
// the map's scale factors. A kernel exception at a singular point gives a
// non-finite result (core/surface.h's contract). Bound boxes a patch for
// the planes, cylinders, cones, spheres, tori, B-spline and Bezier faces
// (docs/MODELS.md, "Bounds of a face's patches").
class FaceSurface final : public Surface {
 public:
  // `closed`: the face's closed form (ClosedForm::Extract), evaluated instead
  // of the kernel; nullopt: the kernel evaluates.
  FaceSurface(const TopoDS_Face& face, const UnitSquareMap& map, std::optional<ClosedForm> closed);

  Vec3 Point(double u, double v) const override;
  SurfaceJet Jet(double u, double v, int order) const override;
  // One adaptor lease a call, not one a point; the same values as Point and
  // Jet, bit for bit.
  void JetGrid(const double* us, int nu, const double* vs, int nv, int order,
               SurfaceJet* out) const override;
  void Points(const double* u, const double* v, size_t n, double* x, double* y,
              double* z) const override;

  // Core's contract (core/surface.h): a box holding Point at every unit-square
  // (u, v) of the patch. A closed-form face: its formula on intervals
  // (ClosedForm::Bound), exact for the double code. Through the kernel: a
  // plane, cylinder, cone, sphere or torus under a transformation by the same
  // formula with the location applied, and a B-spline or Bezier face by the
  // control points of the sub-patch (SpanHull over the kernel's Bezier
  // patches; a periodic B-spline by the poles of the kernel's Segment of a
  // copy, a copy a bound), each widened by kKernelMargin of the face's
  // size for the kernel's rounding. All are arithmetic only or SLEEF's, so
  // the same bits on every CPU. nullopt for every other face (surfaces of
  // revolution and extrusion, offsets, ...), for B-splines of more than
  // kMaxBoundPoles poles, and when the kernel throws.
  std::optional<Box3> Bound(double u0, double u1, double v0, double v1) const override;

  // True when the face is evaluated from its closed form (ClosedForm), not
  // through the kernel's adaptors.
  bool closed_form() const { return closed_.has_value(); }
  // A closed-form plane: its jets' fu, fv are x and y of its placement times
  // the map's constant scales, the same bits everywhere, and its second
  // derivatives zero.
  bool IsAffine() const override {
    return closed_ && closed_->type == ClosedForm::Type::kPlane;
  }

  // Relative widening of a kernel face's bound: the kernel's point is within
  // a few ulp of the exact surface (its de Boor sums and ElSLib's formulas
  // are affine combinations of values of the face's size), and the sub-patch's
  // poles are within a few ulp of the exact ones; 1e-9 is millions of ulp.
  static constexpr double kKernelMargin = 1e-9;
  // B-splines of more poles are not bounded: their Bezier patches take up
  // to (degree + 1)^2 times the memory, and a periodic one's copy is a pass
  // over its poles on every bound (a hostile file could make each bound of a
  // tree build cost milliseconds).
  static constexpr int kMaxBoundPoles = 4096;

 private:
  // Through the kernel's `adaptor`, at unit-square (u, v).
  Vec3 KernelPoint(BRepAdaptor_Surface& adaptor, double u, double v) const;
  SurfaceJet KernelJet(BRepAdaptor_Surface& adaptor, double u, double v, int order) const;
  // From the closed form: the point at unit-square (u, v); the jet at native
  // (u, v), with their cosines and sines, written into `jet` (every field:
  // the second derivatives zero below order 2). Written in place, since a
  // returned jet copied into a grid stalled on store forwarding.
  Vec3 ClosedPoint(double u, double v) const;
  void ClosedJet(double u, double v, const ClosedForm::Trig& tu, const ClosedForm::Trig& tv,
                 int order, SurfaceJet* jet) const;

  // JetGrid of a closed-form plane or cylinder of at most kFactoredSide rows
  // and columns: each row's and column's terms of ClosedJet computed once and
  // added per point in ClosedJet's order (the same bits). False, with
  // nothing written, for any other face or grid.
  bool FactoredGrid(const double* us, int nu, const double* vs, int nv, int order,
                    SurfaceJet* out) const;
  static constexpr int kFactoredSide = 9;

  // The native parameter intervals of the unit-square ones, by map_'s
  // operations on intervals.
  Interval NativeU(double u0, double u1) const;
  Interval NativeV(double v0, double v1) const;
  // The box of the poles of a copy of `spline` segmented to [a0, a1] x
  // [b0, b1] (the kernel's Segment; each end widened by twice the tolerance
  // within which Segment takes it for the knot beside it).
  std::optional<Box3> PolesBound(const Geom_BSplineSurface& spline, double a0, double a1,
                                 double b0, double b1) const;

  const TopoDS_Face face_;
  const UnitSquareMap map_;
  std::optional<ClosedForm> closed_;
  mutable LeasePool<BRepAdaptor_Surface> adaptors_;  // thread-safe
  // For Bound through the kernel, constant after construction and only read
  // (Copy reads its source): at most one of these is set.
  std::optional<ClosedForm> placed_;      // an elementary face under a transformation
  std::optional<SpanHull> spans_;         // a B-spline or Bezier face (located)
  Handle(Geom_BSplineSurface) periodic_;  // a periodic B-spline face (located)
  double kernel_size_ = 0;                // the largest pole coordinate, or the form's size
};

// An axis-aligned box in unit-square parameters.
struct Box2 {
  double s0, s1, t0, t1;
};

// The trim of a face in unit-square parameters. Point classification by
// BRepTopAdaptor_FClass2d; cell classification by a hierarchy of boxes that
// enclose each edge's p-curve (BndLib_Add2dCurve: from the poles for B-spline
// and Bezier p-curves, exact for lines and conics), refined until a box is at
// most kLeafSize of the square. Boxes lying on the square's border are left
// out: a curve there (the outer wire of a face whose UV box is its natural
// box, a seam, a degenerate pole edge) separates nothing inside the square.
class FaceTrim {
 public:
  // `tolerance` is in unit-square parameters.
  FaceTrim(const TopoDS_Face& face, const UnitSquareMap& map, double tolerance);

  bool trimmed() const { return trimmed_; }
  bool Contains(double s, double t) const;
  // Face::KeepsWhole: the grid cells the closed cell meets are all kInside.
  bool KeepsWhole(double s0, double s1, double t0, double t1) const;
  // inside[i] = Contains(s[i], t[i]) for i < n, with one grid check for all.
  void ContainsMany(const double* s, const double* t, size_t n, uint8_t* inside) const;
  CellState Classify(double s0, double s1, double t0, double t1) const;
  // A lower bound on the distance from (s, t) to every trim curve widened by
  // the kernel's ON band: every point closer than it to (s, t), joined to it
  // by a segment no curve crosses, has the same Contains() answer. Refines
  // the curves' boxes near the point (a bounded number of kernel box
  // computations); 0 when it cannot tell.
  double Clearance(double s, double t) const;

  static constexpr double kLeafSize = 1.0 / 2048;
  static constexpr int kMaxDepth = 16;
  // Contains() answers from a kGridSide x kGridSide grid of cells classified
  // once, on first use: cells no curve box touches form pieces, each
  // classified by one kernel answer (as Classify would answer each cell), and
  // asks the kernel only for points in sub-cells the trim may cross.
  static constexpr int kGridSide = 128;
  // A grid cell the boundary may cross is split once more into
  // kFineSide x kFineSide sub-cells (cell width 1/2048, the boxes' size):
  // sub-cells no curve box (widened by the kernel's ON band) touches are
  // flood-filled into connected pieces, and one kernel answer classifies each
  // piece, since no curve separates its points; a piece on the cell's side
  // takes, instead, the answer of a classified cell (or sub-cell) across it
  // (StateAcross), which no curve separates from it either (the box with a
  // hole: 330 kernel answers a face -> 23).
  //
  // Pieces (of cells and of sub-cells) and Clearance() rely on the kernel
  // answering the truth away from the curves, which holds where its polygon's
  // error allowance is exact: trims of lines and circles (the allowance is
  // measured at chord midpoints, where a circle's arc is farthest). On any
  // other trim (B-splines, ellipses, ...) the kernel can be wrong a few
  // sub-cells from the curve, and one wrong answer would spread over a piece;
  // those faces classify each cell at its centre and ask the kernel for
  // every point in the cells a curve may cross, as before pieces existed.
  static constexpr int kFineSide = 16;
  // At most this many cells get sub-cells (256 bytes each); past it the
  // kernel answers the rest point by point.
  static constexpr int kMaxFineCells = 4096;

 private:
  void BuildGrid() const;
  // BuildGrid, once, before the grid is read.
  void EnsureGrid() const;
  // Contains' answer from the grid (and sub-cells), kStraddles where only the
  // exact trim or the kernel can tell. REQUIRES: the grid built.
  CellState GridState(double s, double t) const;
  // Contains' answer for a point GridState leaves kStraddles.
  bool ContainsNearTrim(double s, double t) const;
  void BuildFineGrid(int i, int j) const;
  CellState KernelState(double s, double t) const;
  // KernelState, compared with exact_'s answer (BuildGrid only): a
  // disagreement clears exact_agrees_.
  CellState CheckedKernelState(double s, double t) const;
  // Clears exact_agrees_ if exact_ is sure of (s, t) and differs from `state`.
  void CheckExact(double s, double t, CellState state) const;
  // The state of the grid cells across the sides of grid cell (i, j) that
  // the sub-cells of `piece` (indices in the cell's kFineSide x kFineSide
  // sub-grid) lie on, or of the sub-cells across them in a cell whose
  // sub-cells are classified, where those are classified (not kStraddles)
  // and agree; kStraddles when there is none, or they differ.
  CellState StateAcross(int i, int j, const std::vector<int>& piece) const;
  struct Node {
    Box2 box;
    int first_child = -1;  // children at first_child, first_child + 1; -1 for a leaf
    int edge = 0;          // index into pcurves_
    double a = 0, b = 0;   // the p-curve's parameters the box encloses
  };
  // The box enclosing the p-curve over [a, b], widened by the tolerance.
  Box2 CurveBox(const Adaptor2d_Curve2d& curve, double a, double b) const;
  // The kernel's ON band in unit-square units (twice it, for rounding), per axis.
  double BandS() const;
  double BandT() const;
  bool CrossesBoundary(const Box2& cell) const;
  bool OnBorder(const Box2& box) const;

  const TopoDS_Face face_;
  const UnitSquareMap map_;
  const double tolerance_;
  std::vector<Node> nodes_;  // every edge's hierarchy; roots listed in roots_
  std::vector<int> roots_;
  std::vector<Handle(Geom2d_Curve)> pcurves_;  // one per root, read only
  bool missing_pcurve_ = false;  // an edge without a p-curve: every cell near nothing is unknown
  bool lines_and_circles_ = true;  // every p-curve is a line or a circle (see kFineSide)
  bool trimmed_ = true;
  mutable LeasePool<BRepTopAdaptor_FClass2d> classifiers_;  // thread-safe
  // Faces of lines and circles: Contains() asks it before the kernel. Checked
  // against every answer BuildGrid gives a piece, the kernel's or one taken
  // from across a side (hundreds, many within a few sub-cells of a curve),
  // and dropped there if one differs.
  mutable std::optional<LineCircleTrim> exact_;
  mutable bool exact_agrees_ = true;  // written by BuildGrid only
  mutable std::once_flag grid_once_;
  mutable std::atomic<bool> grid_ready_{false};  // set once grid_once_'s BuildGrid is done
  mutable std::vector<CellState> grid_;  // row s, column t; filled by BuildGrid
  // For grid cell k that the boundary may cross, fine_[fine_at_[k] + a *
  // kFineSide + b] is its sub-cell (a, b); fine_at_[k] = -1 otherwise.
  mutable std::vector<int32_t> fine_at_;
  mutable std::vector<uint8_t> fine_;  // CellState values
};

}  // namespace sfc::cad

#endif  // SFCSAMPLER_CAD_INTERNAL_OCC_FACE_H_
