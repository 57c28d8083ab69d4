#include "cad/internal/occ_face.h"

#include <BRep_Tool.hxx>
#include <BndLib_Add2dCurve.hxx>
#include <Bnd_Box2d.hxx>
#include <Geom2dAdaptor_Curve.hxx>
#include <Geom2d_Curve.hxx>
#include <Standard_Failure.hxx>
#include <TopAbs_State.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Edge.hxx>
#include <algorithm>
#include <cmath>
#include <gp_Pnt.hxx>
#include <gp_Pnt2d.hxx>
#include <gp_Vec.hxx>
#include <limits>

namespace sfc::cad {
namespace {

Vec3 ToVec3(const gp_XYZ& p) { return {p.X(), p.Y(), p.Z()}; }

Vec3 NotFinite() {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  return {nan, nan, nan};
}

bool Intersects(const Box2& a, const Box2& b) {
  return a.s0 <= b.s1 && b.s0 <= a.s1 && a.t0 <= b.t1 && b.t0 <= a.t1;
}

}  // namespace

FaceSurface::FaceSurface(const TopoDS_Face& face, const UnitSquareMap& map)
    : face_(face),
      map_(map),
      adaptors_([face] { return std::make_unique<BRepAdaptor_Surface>(face, true); }) {}

Vec3 FaceSurface::Point(double u, double v) const {
  auto adaptor = adaptors_.Take();
  try {
    return ToVec3(adaptor->Value(map_.U(u), map_.V(v)).XYZ());
  } catch (const Standard_Failure&) {
    return NotFinite();
  }
}

SurfaceJet FaceSurface::Jet(double u, double v, int order) const {
  auto adaptor = adaptors_.Take();
  SurfaceJet jet;
  const double su = map_.DuDs(), sv = map_.DvDt();
  try {
    gp_Pnt p;
    gp_Vec du, dv;
    if (order >= 2) {
      gp_Vec duu, dvv, duv;
      adaptor->D2(map_.U(u), map_.V(v), p, du, dv, duu, dvv, duv);
      jet.fuu = ToVec3(duu.XYZ()) * (su * su);
      jet.fuv = ToVec3(duv.XYZ()) * (su * sv);
      jet.fvv = ToVec3(dvv.XYZ()) * (sv * sv);
    } else {
      adaptor->D1(map_.U(u), map_.V(v), p, du, dv);
    }
    jet.p = ToVec3(p.XYZ());
    jet.fu = ToVec3(du.XYZ()) * su;
    jet.fv = ToVec3(dv.XYZ()) * sv;
  } catch (const Standard_Failure&) {
    jet.p = jet.fu = jet.fv = NotFinite();
  }
  return jet;
}

FaceTrim::FaceTrim(const TopoDS_Face& face, const UnitSquareMap& map, double tolerance)
    : face_(face), map_(map), tolerance_(tolerance), classifiers_([face, map, tolerance] {
        const double native =
            tolerance * std::max(map.box.u1 - map.box.u0, map.box.v1 - map.box.v0);
        return std::make_unique<BRepTopAdaptor_FClass2d>(face, native);
      }) {
  // One box hierarchy per edge's p-curve, built breadth-first into nodes_.
  for (TopExp_Explorer it(face, TopAbs_EDGE); it.More(); it.Next()) {
    const TopoDS_Edge& edge = TopoDS::Edge(it.Current());
    double first = 0, last = 0;
    Handle(Geom2d_Curve) pcurve = BRep_Tool::CurveOnSurface(edge, face, first, last);
    if (pcurve.IsNull()) {
      missing_pcurve_ = true;
      continue;
    }
    const Geom2dAdaptor_Curve curve(pcurve);
    auto box_of = [&](double a, double b) {
      Bnd_Box2d bnd;
      BndLib_Add2dCurve::Add(curve, a, b, 0.0, bnd);
      double umin, vmin, umax, vmax;
      bnd.Get(umin, vmin, umax, vmax);
      double s0 = map_.S(umin), s1 = map_.S(umax);
      if (s0 > s1) std::swap(s0, s1);
      const double m = tolerance_;
      return Box2{s0 - m, s1 + m, map_.T(vmin) - m, map_.T(vmax) + m};
    };
    struct Pending {
      int node;
      double a, b;
      int depth;
    };
    std::vector<Pending> queue;
    roots_.push_back(static_cast<int>(nodes_.size()));
    nodes_.push_back({box_of(first, last), -1});
    queue.push_back({roots_.back(), first, last, 0});
    for (size_t q = 0; q < queue.size(); ++q) {
      const Pending p = queue[q];
      const Box2 box = nodes_[p.node].box;
      const bool small = std::max(box.s1 - box.s0, box.t1 - box.t0) <= kLeafSize;
      if (small || p.depth >= kMaxDepth || OnBorder(box)) continue;
      const double mid = 0.5 * (p.a + p.b);
      const int child = static_cast<int>(nodes_.size());
      nodes_[p.node].first_child = child;
      nodes_.push_back({box_of(p.a, mid), -1});
      nodes_.push_back({box_of(mid, p.b), -1});
      queue.push_back({child, p.a, mid, p.depth + 1});
      queue.push_back({child + 1, mid, p.b, p.depth + 1});
    }
  }
  // A face whose every trim curve lies on the square's border, and whose
  // centre is in it, is the whole square.
  bool interior_curve = missing_pcurve_;
  for (int root : roots_) interior_curve = interior_curve || !OnBorder(nodes_[root].box);
  if (!interior_curve) {
    auto classifier = classifiers_.Take();
    trimmed_ = classifier->Perform(gp_Pnt2d(map_.U(0.5), map_.V(0.5))) != TopAbs_IN;
  }
}

bool FaceTrim::OnBorder(const Box2& box) const {
  const double e = 1e-7 + 2 * tolerance_;
  return box.s1 <= e || box.s0 >= 1 - e || box.t1 <= e || box.t0 >= 1 - e;
}

bool FaceTrim::CrossesBoundary(const Box2& cell) const {
  if (missing_pcurve_) return true;
  std::vector<int> stack(roots_.begin(), roots_.end());
  while (!stack.empty()) {
    const Node& node = nodes_[stack.back()];
    stack.pop_back();
    if (!Intersects(node.box, cell) || OnBorder(node.box)) continue;
    if (node.first_child < 0) return true;
    stack.push_back(node.first_child);
    stack.push_back(node.first_child + 1);
  }
  return false;
}

void FaceTrim::BuildGrid() const {
  grid_.resize(kGridSide * kGridSide);
  for (int i = 0; i < kGridSide; ++i) {
    for (int j = 0; j < kGridSide; ++j) {
      grid_[i * kGridSide + j] = Classify(double(i) / kGridSide, double(i + 1) / kGridSide,
                                          double(j) / kGridSide, double(j + 1) / kGridSide);
    }
  }
}

bool FaceTrim::Contains(double s, double t) const {
  if (!trimmed_) return true;
  std::call_once(grid_once_, [this] { BuildGrid(); });
  const int i = std::clamp(static_cast<int>(s * kGridSide), 0, kGridSide - 1);
  const int j = std::clamp(static_cast<int>(t * kGridSide), 0, kGridSide - 1);
  switch (grid_[i * kGridSide + j]) {
    case CellState::kInside: return true;
    case CellState::kOutside: return false;
    case CellState::kStraddles: break;
  }
  auto classifier = classifiers_.Take();
  try {
    return classifier->Perform(gp_Pnt2d(map_.U(s), map_.V(t))) != TopAbs_OUT;
  } catch (const Standard_Failure&) {
    return false;
  }
}

CellState FaceTrim::Classify(double s0, double s1, double t0, double t1) const {
  if (!trimmed_) return CellState::kInside;
  if (CrossesBoundary({s0, s1, t0, t1})) return CellState::kStraddles;
  auto classifier = classifiers_.Take();
  try {
    switch (classifier->Perform(gp_Pnt2d(map_.U(0.5 * (s0 + s1)), map_.V(0.5 * (t0 + t1))))) {
      case TopAbs_IN:
        return CellState::kInside;
      case TopAbs_OUT:
        return CellState::kOutside;
      default:
        return CellState::kStraddles;
    }
  } catch (const Standard_Failure&) {
    return CellState::kStraddles;
  }
}

}  // namespace sfc::cad
