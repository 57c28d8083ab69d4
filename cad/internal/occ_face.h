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

#include <BRepAdaptor_Surface.hxx>
#include <BRepTopAdaptor_FClass2d.hxx>
#include <TopoDS_Face.hxx>
#include <functional>
#include <memory>
#include <mutex>
#include <vector>

#include "absl/base/thread_annotations.h"
#include "absl/synchronization/mutex.h"
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
// non-finite result (core/surface.h's contract).
class FaceSurface final : public Surface {
 public:
  FaceSurface(const TopoDS_Face& face, const UnitSquareMap& map);

  Vec3 Point(double u, double v) const override;
  SurfaceJet Jet(double u, double v, int order) const override;

 private:
  const TopoDS_Face face_;
  const UnitSquareMap map_;
  mutable LeasePool<BRepAdaptor_Surface> adaptors_;  // thread-safe
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
  CellState Classify(double s0, double s1, double t0, double t1) const;

  static constexpr double kLeafSize = 1.0 / 2048;
  static constexpr int kMaxDepth = 16;
  // Contains() answers from a kGridSide x kGridSide grid of cells classified
  // once, on first use (Classify: conservative), and asks the kernel only for
  // points in cells the trim may cross.
  static constexpr int kGridSide = 128;

 private:
  void BuildGrid() const;
  struct Node {
    Box2 box;
    int first_child = -1;  // children at first_child, first_child + 1; -1 for a leaf
  };
  bool CrossesBoundary(const Box2& cell) const;
  bool OnBorder(const Box2& box) const;

  const TopoDS_Face face_;
  const UnitSquareMap map_;
  const double tolerance_;
  std::vector<Node> nodes_;  // every edge's hierarchy; roots listed in roots_
  std::vector<int> roots_;
  bool missing_pcurve_ = false;  // an edge without a p-curve: every cell near nothing is unknown
  bool trimmed_ = true;
  mutable LeasePool<BRepTopAdaptor_FClass2d> classifiers_;  // thread-safe
  mutable std::once_flag grid_once_;
  mutable std::vector<CellState> grid_;  // row s, column t; filled by BuildGrid
};

}  // namespace sfc::cad

#endif  // SFCSAMPLER_CAD_INTERNAL_OCC_FACE_H_
