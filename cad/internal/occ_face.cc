#include "cad/internal/occ_face.h"

#include <BRep_Tool.hxx>
#include <BndLib_Add2dCurve.hxx>
#include <GeomConvert_BSplineSurfaceToBezierSurface.hxx>
#include <Geom_BezierSurface.hxx>
#include <TColStd_Array1OfReal.hxx>
#include <Bnd_Box2d.hxx>
#include <Geom2dAdaptor_Curve.hxx>
#include <Geom2d_Curve.hxx>
#include <Precision.hxx>
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
#include <queue>

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

// Gives every unmarked cell of a side x side grid (row-major) the state of
// its piece, the unmarked cells joined to it by sides, which
// `classify(k, piece)` answers for the piece's first cell k (and its cells,
// `piece`); marked cells get kStraddles.
template <typename State, typename Classify>
void ClassifyPieces(const std::vector<char>& marked, int side, State* out,
                    const Classify& classify) {
  const int cells = side * side;
  std::vector<char> seen(cells, 0);
  std::vector<int> piece;
  for (int start = 0; start < cells; ++start) {
    if (marked[start]) out[start] = static_cast<State>(CellState::kStraddles);
    if (marked[start] || seen[start]) continue;
    piece.assign(1, start);
    seen[start] = 1;
    for (size_t q = 0; q < piece.size(); ++q) {
      const int a = piece[q] / side, c = piece[q] % side;
      const int next[4][2] = {{a - 1, c}, {a + 1, c}, {a, c - 1}, {a, c + 1}};
      for (const auto& n : next) {
        if (n[0] < 0 || n[0] >= side || n[1] < 0 || n[1] >= side) continue;
        const int k = n[0] * side + n[1];
        if (!marked[k] && !seen[k]) seen[k] = 1, piece.push_back(k);
      }
    }
    const State state = static_cast<State>(classify(start, piece));
    for (int k : piece) out[k] = state;
  }
}

// Marks, in a side x side grid of cells of width w from (s0, t0), the cells
// the box touches (closed).
void MarkBox(const Box2& b, double s0, double t0, double w, int side, std::vector<char>* marked) {
  auto index = [&](double x, double x0) {
    return std::clamp(static_cast<int>(std::floor((x - x0) / w)), 0, side - 1);
  };
  if (b.s1 < s0 || b.s0 > s0 + side * w || b.t1 < t0 || b.t0 > t0 + side * w) return;
  for (int a = index(b.s0, s0); a <= index(b.s1, s0); ++a) {
    for (int c = index(b.t0, t0); c <= index(b.t1, t0); ++c) (*marked)[a * side + c] = 1;
  }
}

}  // namespace

FaceSurface::FaceSurface(const TopoDS_Face& face, const UnitSquareMap& map,
                         std::optional<ClosedForm> closed)
    : face_(face),
      map_(map),
      closed_(std::move(closed)),
      adaptors_([face] { return std::make_unique<BRepAdaptor_Surface>(face, true); }) {
  if (closed_) return;
  try {
    const BRepAdaptor_Surface adaptor(face, true);
    auto note_size = [this](const gp_Pnt& p) {
      kernel_size_ = std::max({kernel_size_, std::abs(p.X()), std::abs(p.Y()), std::abs(p.Z())});
    };
    // The Bezier patches' homogeneous control points, for SpanHull.
    std::vector<double> points;
    int pu = 0, pv = 0;
    auto add_patch = [&](const Geom_BezierSurface& patch) {
      pu = patch.NbUPoles(), pv = patch.NbVPoles();
      for (int i = 1; i <= pu; ++i) {
        for (int j = 1; j <= pv; ++j) {
          const gp_Pnt& p = patch.Pole(i, j);
          const double w = patch.Weight(i, j);
          points.insert(points.end(), {w * p.X(), w * p.Y(), w * p.Z(), w});
          note_size(p);
        }
      }
    };
    const bool small =
        adaptor.GetType() != GeomAbs_BSplineSurface && adaptor.GetType() != GeomAbs_BezierSurface
            ? true
            : adaptor.NbUPoles() * static_cast<int64_t>(adaptor.NbVPoles()) <= kMaxBoundPoles;
    switch (small ? adaptor.GetType() : GeomAbs_OtherSurface) {
      case GeomAbs_BSplineSurface: {
        const Handle(Geom_BSplineSurface) bspline = adaptor.BSpline();
        if (bspline->IsUPeriodic() || bspline->IsVPeriodic()) {
          periodic_ = bspline;
          for (int i = 1; i <= bspline->NbUPoles(); ++i) {
            for (int j = 1; j <= bspline->NbVPoles(); ++j) note_size(bspline->Pole(i, j));
          }
          break;
        }
        GeomConvert_BSplineSurfaceToBezierSurface convert(bspline);
        TColStd_Array1OfReal uk(1, convert.NbUPatches() + 1), vk(1, convert.NbVPatches() + 1);
        convert.UKnots(uk);
        convert.VKnots(vk);
        for (int a = 1; a <= convert.NbUPatches(); ++a) {
          for (int b = 1; b <= convert.NbVPatches(); ++b) add_patch(*convert.Patch(a, b));
        }
        spans_.emplace(std::vector<double>(uk.begin(), uk.end()),
                       std::vector<double>(vk.begin(), vk.end()), pu, pv, std::move(points));
        break;
      }
      case GeomAbs_BezierSurface:
        add_patch(*adaptor.Bezier());
        spans_.emplace(std::vector<double>{0, 1}, std::vector<double>{0, 1}, pu, pv,
                       std::move(points));
        break;
      case GeomAbs_OtherSurface:
        break;
      default:
        placed_ = ClosedForm::FormOf(adaptor);
        if (placed_) {
          kernel_size_ = std::max({std::abs(placed_->o[0]), std::abs(placed_->o[1]),
                                   std::abs(placed_->o[2])}) +
                         std::abs(placed_->radius) + std::abs(placed_->minor);
        }
    }
  } catch (const Standard_Failure&) {
    placed_.reset(), spans_.reset(), periodic_.Nullify();
  }
  if (!std::isfinite(kernel_size_)) placed_.reset(), spans_.reset(), periodic_.Nullify();
}

Interval FaceSurface::NativeU(double u0, double u1) const {
  const Interval width = Interval::Point(map_.box.u1 - map_.box.u0);
  return map_.reversed ? Interval::Point(map_.box.u1) - Interval::Of(u0, u1) * width
                       : Interval::Point(map_.box.u0) + Interval::Of(u0, u1) * width;
}

Interval FaceSurface::NativeV(double v0, double v1) const {
  return Interval::Point(map_.box.v0) +
         Interval::Of(v0, v1) * Interval::Point(map_.box.v1 - map_.box.v0);
}

std::optional<Box3> FaceSurface::PolesBound(const Geom_BSplineSurface& spline, double a0,
                                            double a1, double b0, double b1) const {
  double first_u, last_u, first_v, last_v;
  spline.Bounds(first_u, last_u, first_v, last_v);
  const double tolerance = Precision::PConfusion();
  auto clamp = [&](double* lo, double* hi, double first, double last, bool periodic) {
    *lo -= 2 * tolerance, *hi += 2 * tolerance;
    if (!periodic) *lo = std::max(*lo, first), *hi = std::min(*hi, last);
    return *lo < *hi;
  };
  if (!clamp(&a0, &a1, first_u, last_u, spline.IsUPeriodic()) ||
      !clamp(&b0, &b1, first_v, last_v, spline.IsVPeriodic())) {
    return std::nullopt;
  }
  const Handle(Geom_BSplineSurface) piece = Handle(Geom_BSplineSurface)::DownCast(spline.Copy());
  piece->Segment(a0, a1, b0, b1, tolerance, tolerance);
  Vec3 lo{INFINITY, INFINITY, INFINITY}, hi{-INFINITY, -INFINITY, -INFINITY};
  for (int i = 1; i <= piece->NbUPoles(); ++i) {
    for (int j = 1; j <= piece->NbVPoles(); ++j) {
      const gp_Pnt& p = piece->Pole(i, j);
      lo = {std::min(lo.x, p.X()), std::min(lo.y, p.Y()), std::min(lo.z, p.Z())};
      hi = {std::max(hi.x, p.X()), std::max(hi.y, p.Y()), std::max(hi.z, p.Z())};
    }
  }
  return Box3{lo, hi};
}

std::optional<Box3> FaceSurface::Bound(double u0, double u1, double v0, double v1) const {
  const Interval u = NativeU(u0, u1), v = NativeV(v0, v1);
  if (closed_) return closed_->Bound(u, v);
  std::optional<Box3> box;
  try {
    if (placed_) {
      box = placed_->Bound(u, v);
    } else if (spans_) {
      box = spans_->Bound(u.lo, u.hi, v.lo, v.hi);
    } else if (!periodic_.IsNull()) {
      box = PolesBound(*periodic_, u.lo, u.hi, v.lo, v.hi);
    }
  } catch (const Standard_Failure&) {
    return std::nullopt;
  }
  if (!box) return std::nullopt;
  // The kernel's rounding: kKernelMargin of the face's size, of the box's
  // and, for a plane or a cylinder, of the parameters' (which a point's
  // terms are multiples of).
  const double size = std::max(
      {kernel_size_, std::abs(box->lo.x), std::abs(box->lo.y), std::abs(box->lo.z),
       std::abs(box->hi.x), std::abs(box->hi.y), std::abs(box->hi.z),
       placed_ ? std::max({std::abs(u.lo), std::abs(u.hi), std::abs(v.lo), std::abs(v.hi)}) : 0});
  const double margin = kKernelMargin * size;
  if (!std::isfinite(margin)) return std::nullopt;
  box->lo = {box->lo.x - margin, box->lo.y - margin, box->lo.z - margin};
  box->hi = {box->hi.x + margin, box->hi.y + margin, box->hi.z + margin};
  return box;
}

Vec3 FaceSurface::KernelPoint(BRepAdaptor_Surface& adaptor, double u, double v) const {
  try {
    return ToVec3(adaptor.Value(map_.U(u), map_.V(v)).XYZ());
  } catch (const Standard_Failure&) {
    return NotFinite();
  }
}

SurfaceJet FaceSurface::KernelJet(BRepAdaptor_Surface& adaptor, double u, double v,
                                  int order) const {
  SurfaceJet jet;
  const double su = map_.DuDs(), sv = map_.DvDt();
  try {
    gp_Pnt p;
    gp_Vec du, dv;
    if (order >= 2) {
      gp_Vec duu, dvv, duv;
      adaptor.D2(map_.U(u), map_.V(v), p, du, dv, duu, dvv, duv);
      jet.fuu = ToVec3(duu.XYZ()) * (su * su);
      jet.fuv = ToVec3(duv.XYZ()) * (su * sv);
      jet.fvv = ToVec3(dvv.XYZ()) * (sv * sv);
    } else {
      adaptor.D1(map_.U(u), map_.V(v), p, du, dv);
    }
    jet.p = ToVec3(p.XYZ());
    jet.fu = ToVec3(du.XYZ()) * su;
    jet.fv = ToVec3(dv.XYZ()) * sv;
  } catch (const Standard_Failure&) {
    jet.p = jet.fu = jet.fv = NotFinite();
  }
  return jet;
}

Vec3 FaceSurface::ClosedPoint(double u, double v) const {
  double d[6][3];
  closed_->Evaluate(map_.U(u), map_.V(v), 0, d);
  return {d[0][0], d[0][1], d[0][2]};
}

void FaceSurface::ClosedJet(double u, double v, const ClosedForm::Trig& tu,
                            const ClosedForm::Trig& tv, int order, SurfaceJet* jet) const {
  double d[6][3];
  closed_->EvaluateWith(u, v, tu, tv, order >= 2 ? 2 : 1, d);
  auto vec = [](const double* e) { return Vec3{e[0], e[1], e[2]}; };
  const double su = map_.DuDs(), sv = map_.DvDt();
  jet->p = vec(d[0]);
  jet->fu = vec(d[1]) * su;
  jet->fv = vec(d[2]) * sv;
  if (order >= 2) {
    jet->fuu = vec(d[3]) * (su * su);
    jet->fuv = vec(d[5]) * (su * sv);
    jet->fvv = vec(d[4]) * (sv * sv);
  } else {
    jet->fuu = jet->fuv = jet->fvv = Vec3{};
  }
}

Vec3 FaceSurface::Point(double u, double v) const {
  return closed_ ? ClosedPoint(u, v) : KernelPoint(*adaptors_.Take(), u, v);
}

SurfaceJet FaceSurface::Jet(double u, double v, int order) const {
  if (!closed_) return KernelJet(*adaptors_.Take(), u, v, order);
  const double nu = map_.U(u), nv = map_.V(v);
  SurfaceJet jet;
  ClosedJet(nu, nv, closed_->TrigU(nu), closed_->TrigV(nv), order, &jet);
  return jet;
}

void FaceSurface::JetGrid(const double* us, int nu, const double* vs, int nv, int order,
                          SurfaceJet* out) const {
  if (!closed_) {
    auto adaptor = adaptors_.Take();
    for (int i = 0; i < nu; ++i) {
      for (int j = 0; j < nv; ++j) out[i * nv + j] = KernelJet(*adaptor, us[i], vs[j], order);
    }
    return;
  }
  if (FactoredGrid(us, nu, vs, nv, order, out)) return;
  // The cosines and sines once a row and once a column, not once a point,
  // all in one batch (ClosedForm::TrigsOf: the same bits as TrigU and
  // TrigV). The tree build asks for 3 x 3 grids: no allocation for those.
  const int n = nu + nv;
  double a_on_stack[16];
  ClosedForm::Trig t_on_stack[16];
  std::vector<double> a_on_heap(n > 16 ? n : 0);
  std::vector<ClosedForm::Trig> t_on_heap(n > 16 ? n : 0);
  double* a = n > 16 ? a_on_heap.data() : a_on_stack;
  ClosedForm::Trig* t = n > 16 ? t_on_heap.data() : t_on_stack;
  for (int i = 0; i < nu; ++i) a[i] = map_.U(us[i]);
  for (int j = 0; j < nv; ++j) a[nu + j] = map_.V(vs[j]);
  const int trigs = closed_->TakesTrigV() ? n : closed_->TakesTrigU() ? nu : 0;
  ClosedForm::TrigsOf(a, trigs, t);
  std::fill(t + trigs, t + n, ClosedForm::Trig{});
  for (int i = 0; i < nu; ++i) {
    for (int j = 0; j < nv; ++j) {
      ClosedJet(a[i], a[nu + j], t[i], t[nu + j], order, &out[i * nv + j]);
    }
  }
}

bool FaceSurface::FactoredGrid(const double* us, int nu, const double* vs, int nv, int order,
                               SurfaceJet* out) const {
  const ClosedForm& f = *closed_;
  const bool plane = f.type == ClosedForm::Type::kPlane;
  if ((!plane && f.type != ClosedForm::Type::kCylinder) || nu > kFactoredSide ||
      nv > kFactoredSide) {
    return false;
  }
  const double su = map_.DuDs(), sv = map_.DvDt();
  // A row's part of the point (a plane's u x, a cylinder's a1 x + a2 y) and
  // its derivatives, and a column's v y or v z: EvaluateWith's terms, each
  // computed once, then added in its order. Plain arrays: arrays of Vec3
  // would be zeroed first (a `rep stos` as costly as the rest).
  double row[kFactoredSide][3], fu[kFactoredSide][3], fuu[kFactoredSide][3];
  double native[kFactoredSide] = {};
  ClosedForm::Trig trig[kFactoredSide];
  for (int i = 0; i < nu; ++i) native[i] = map_.U(us[i]);
  if (!plane) ClosedForm::TrigsOf(native, nu, trig);
  for (int i = 0; i < nu; ++i) {
    if (plane) {
      for (int k = 0; k < 3; ++k) {
        row[i][k] = native[i] * f.x[k];
        fu[i][k] = f.x[k] * su;
        fuu[i][k] = 0.0 * (su * su);
      }
      continue;
    }
    const double a1 = f.radius * trig[i].cos, a2 = f.radius * trig[i].sin;
    for (int k = 0; k < 3; ++k) {
      const double som = a1 * f.x[k] + a2 * f.y[k];
      row[i][k] = som;
      fu[i][k] = (-a2 * f.x[k] + a1 * f.y[k]) * su;
      fuu[i][k] = -som * (su * su);
    }
  }
  const double* across = plane ? f.y : f.z;
  const Vec3 fv{across[0] * sv, across[1] * sv, across[2] * sv};
  const double uv = 0.0 * (su * sv), vv = 0.0 * (sv * sv);
  const Vec3 fuv{uv, uv, uv}, fvv{vv, vv, vv};
  for (int j = 0; j < nv; ++j) {
    const double v = map_.V(vs[j]);
    const double col[3] = {v * across[0], v * across[1], v * across[2]};
    for (int i = 0; i < nu; ++i) {
      SurfaceJet& jet = out[i * nv + j];
      jet.p = Vec3{row[i][0] + col[0] + f.o[0], row[i][1] + col[1] + f.o[1],
                   row[i][2] + col[2] + f.o[2]};
      jet.fu = Vec3{fu[i][0], fu[i][1], fu[i][2]};
      jet.fv = fv;
      if (order >= 2) {
        jet.fuu = Vec3{fuu[i][0], fuu[i][1], fuu[i][2]}, jet.fuv = fuv, jet.fvv = fvv;
      } else {
        jet.fuu = jet.fuv = jet.fvv = Vec3{};
      }
    }
  }
  return true;
}

void FaceSurface::Points(const double* u, const double* v, size_t n, double* x, double* y,
                         double* z) const {
  auto fill = [&](auto point) {
    for (size_t i = 0; i < n; ++i) {
      const Vec3 p = point(u[i], v[i]);
      x[i] = p.x, y[i] = p.y, z[i] = p.z;
    }
  };
  if (closed_) {
    // Native parameters a chunk at a time, then the closed form's loop.
    constexpr size_t kChunk = 256;
    double nu[kChunk], nv[kChunk];
    for (size_t b = 0; b < n; b += kChunk) {
      const size_t m = std::min(kChunk, n - b);
      for (size_t i = 0; i < m; ++i) nu[i] = map_.U(u[b + i]), nv[i] = map_.V(v[b + i]);
      closed_->Points(nu, nv, m, x + b, y + b, z + b);
    }
    return;
  }
  auto adaptor = adaptors_.Take();
  fill([&](double s, double t) { return KernelPoint(*adaptor, s, t); });
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
    lines_and_circles_ = lines_and_circles_ &&
                         (curve.GetType() == GeomAbs_Line || curve.GetType() == GeomAbs_Circle);
    const int edge_index = static_cast<int>(pcurves_.size());
    pcurves_.push_back(pcurve);
    struct Pending {
      int node;
      double a, b;
      int depth;
    };
    std::vector<Pending> queue;
    roots_.push_back(static_cast<int>(nodes_.size()));
    nodes_.push_back({CurveBox(curve, first, last), -1, edge_index, first, last});
    queue.push_back({roots_.back(), first, last, 0});
    for (size_t q = 0; q < queue.size(); ++q) {
      const Pending p = queue[q];
      const Box2 box = nodes_[p.node].box;
      const bool small = std::max(box.s1 - box.s0, box.t1 - box.t0) <= kLeafSize;
      if (small || p.depth >= kMaxDepth || OnBorder(box)) continue;
      const double mid = 0.5 * (p.a + p.b);
      const int child = static_cast<int>(nodes_.size());
      nodes_[p.node].first_child = child;
      nodes_.push_back({CurveBox(curve, p.a, mid), -1, edge_index, p.a, mid});
      nodes_.push_back({CurveBox(curve, mid, p.b), -1, edge_index, mid, p.b});
      queue.push_back({child, p.a, mid, p.depth + 1});
      queue.push_back({child + 1, mid, p.b, p.depth + 1});
    }
  }
  if (lines_and_circles_ && !missing_pcurve_) {
    exact_ = LineCircleTrim::Extract(
        face, 1e-6 * std::max(map.box.u1 - map.box.u0, map.box.v1 - map.box.v0));
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

Box2 FaceTrim::CurveBox(const Adaptor2d_Curve2d& curve, double a, double b) const {
  Bnd_Box2d bnd;
  BndLib_Add2dCurve::Add(curve, a, b, 0.0, bnd);
  double umin, vmin, umax, vmax;
  bnd.Get(umin, vmin, umax, vmax);
  double s0 = map_.S(umin), s1 = map_.S(umax);
  if (s0 > s1) std::swap(s0, s1);
  const double m = tolerance_;
  return Box2{s0 - m, s1 + m, map_.T(vmin) - m, map_.T(vmax) + m};
}

double FaceTrim::BandS() const {
  const double du = map_.box.u1 - map_.box.u0, dv = map_.box.v1 - map_.box.v0;
  return 2 * tolerance_ * std::max(du, dv) / du + 1e-12;
}

double FaceTrim::BandT() const {
  const double du = map_.box.u1 - map_.box.u0, dv = map_.box.v1 - map_.box.v0;
  return 2 * tolerance_ * std::max(du, dv) / dv + 1e-12;
}

double FaceTrim::Clearance(double s, double t) const {
  if (!trimmed_ || missing_pcurve_ || !lines_and_circles_) return 0;
  const double ms = BandS(), mt = BandT();
  struct Piece {
    double distance;
    Box2 box;
    int node;  // the hierarchy's node, or -1 for a piece split below a leaf
    int edge;
    double a, b;
    bool operator>(const Piece& o) const { return distance > o.distance; }
  };
  auto piece = [&](const Box2& box, int node, int edge, double a, double b) {
    const Box2 w{box.s0 - ms, box.s1 + ms, box.t0 - mt, box.t1 + mt};
    const double ds = std::max({w.s0 - s, s - w.s1, 0.0});
    const double dt = std::max({w.t0 - t, t - w.t1, 0.0});
    // sqrt, not hypot: correctly rounded, so the same bits everywhere.
    return Piece{std::sqrt(ds * ds + dt * dt), w, node, edge, a, b};
  };
  auto of_node = [&](int n) {
    const Node& node = nodes_[n];
    return piece(node.box, n, node.edge, node.a, node.b);
  };
  // Best first: the nearest box is split (the hierarchy's children, then the
  // kernel's boxes of halves) until it is small against its distance; its
  // distance then bounds every curve's from below.
  std::priority_queue<Piece, std::vector<Piece>, std::greater<Piece>> queue;
  for (int root : roots_) queue.push(of_node(root));
  constexpr int kMaxSplits = 512;
  for (int splits = 0; !queue.empty(); ++splits) {
    const Piece near = queue.top();
    const double size = std::max(near.box.s1 - near.box.s0, near.box.t1 - near.box.t0);
    if (size <= 0.25 * near.distance || size < 1e-10 || splits == kMaxSplits) {
      return near.distance;
    }
    queue.pop();
    if (near.node >= 0 && nodes_[near.node].first_child >= 0) {
      queue.push(of_node(nodes_[near.node].first_child));
      queue.push(of_node(nodes_[near.node].first_child + 1));
      continue;
    }
    const Geom2dAdaptor_Curve curve(pcurves_[near.edge]);
    const double mid = 0.5 * (near.a + near.b);
    try {
      queue.push(piece(CurveBox(curve, near.a, mid), -1, near.edge, near.a, mid));
      queue.push(piece(CurveBox(curve, mid, near.b), -1, near.edge, mid, near.b));
    } catch (const Standard_Failure&) {
      return 0;
    }
  }
  return std::numeric_limits<double>::infinity();  // no curve at all
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
  constexpr int kCells = kGridSide * kGridSide;
  grid_.assign(kCells, CellState::kStraddles);
  fine_at_.assign(kCells, -1);
  if (missing_pcurve_) return;  // every cell may hold a curve we cannot see
  if (!lines_and_circles_) {
    for (int k = 0; k < kCells; ++k) {
      const int i = k / kGridSide, j = k % kGridSide;
      grid_[k] = Classify(double(i) / kGridSide, double(i + 1) / kGridSide, double(j) / kGridSide,
                          double(j + 1) / kGridSide);
    }
    return;
  }
  // The cells a curve box not on the square's border touches, boxes widened
  // by the kernel's ON band; the other cells form pieces no curve crosses,
  // and the kernel's answer at the centre of a piece's first cell holds for
  // all of it (as Classify, a cell at a time, would answer).
  const double ms = BandS(), mt = BandT();
  std::vector<char> marked(kCells, 0);
  for (const Node& node : nodes_) {
    if (node.first_child >= 0 || OnBorder(node.box)) continue;
    MarkBox({node.box.s0 - ms, node.box.s1 + ms, node.box.t0 - mt, node.box.t1 + mt}, 0, 0,
            1.0 / kGridSide, kGridSide, &marked);
  }
  ClassifyPieces(marked, kGridSide, grid_.data(), [&](int k, const std::vector<int>&) {
    return CheckedKernelState((k / kGridSide + 0.5) / kGridSide,
                              (k % kGridSide + 0.5) / kGridSide);
  });
  int fine_cells = 0;
  for (int k = 0; k < kCells && fine_cells < kMaxFineCells; ++k) {
    if (grid_[k] != CellState::kStraddles) continue;
    BuildFineGrid(k / kGridSide, k % kGridSide);
    ++fine_cells;
  }
  if (!exact_agrees_) exact_.reset();
}

CellState FaceTrim::CheckedKernelState(double s, double t) const {
  const CellState state = KernelState(s, t);
  CheckExact(s, t, state);
  return state;
}

void FaceTrim::CheckExact(double s, double t, CellState state) const {
  if (!exact_) return;
  const LineCircleTrim::Side side = exact_->Classify(map_.U(s), map_.V(t));
  if (side != LineCircleTrim::Side::kUnsure &&
      (side == LineCircleTrim::Side::kIn) != (state != CellState::kOutside)) {
    exact_agrees_ = false;
  }
}

CellState FaceTrim::StateAcross(int i, int j, const std::vector<int>& piece) const {
  CellState found = CellState::kStraddles;
  for (int k : piece) {
    const int a = k / kFineSide, c = k % kFineSide;
    const int across[4][3] = {{a == 0, i - 1, j},
                              {a == kFineSide - 1, i + 1, j},
                              {c == 0, i, j - 1},
                              {c == kFineSide - 1, i, j + 1}};
    for (const auto& n : across) {
      if (!n[0] || n[1] < 0 || n[1] >= kGridSide || n[2] < 0 || n[2] >= kGridSide) continue;
      const int cell = n[1] * kGridSide + n[2];
      CellState state = grid_[cell];
      if (state == CellState::kStraddles && fine_at_[cell] >= 0) {
        // A cell with sub-cells already classified: the sub-cell across.
        const int sa = n[1] != i ? kFineSide - 1 - a : a, sc = n[2] != j ? kFineSide - 1 - c : c;
        state = static_cast<CellState>(fine_[fine_at_[cell] + sa * kFineSide + sc]);
      }
      if (state == CellState::kStraddles) continue;
      // Two answers that differ (a kernel wrong somewhere): ask it here.
      if (found != CellState::kStraddles && state != found) return CellState::kStraddles;
      found = state;
    }
  }
  return found;
}

void FaceTrim::BuildFineGrid(int i, int j) const {
  constexpr int kCells = kFineSide * kFineSide;
  const double w = 1.0 / (kGridSide * kFineSide);
  const double s0 = double(i) / kGridSide, t0 = double(j) / kGridSide;
  // Every curve box (the hierarchy's leaves, border ones included), widened
  // by twice the kernel's ON band in each axis (its tolerance is isotropic in
  // the native parameters), marks the sub-cells it touches; one kernel answer
  // classifies each piece of the others.
  const double ms = BandS(), mt = BandT();
  const Box2 cell{s0, s0 + 1.0 / kGridSide, t0, t0 + 1.0 / kGridSide};
  std::vector<char> marked(kCells, 0);
  std::vector<int> stack(roots_.begin(), roots_.end());
  while (!stack.empty()) {
    const Node& node = nodes_[stack.back()];
    stack.pop_back();
    const Box2 b{node.box.s0 - ms, node.box.s1 + ms, node.box.t0 - mt, node.box.t1 + mt};
    if (!Intersects(b, cell)) continue;
    if (node.first_child >= 0) {
      stack.push_back(node.first_child);
      stack.push_back(node.first_child + 1);
      continue;
    }
    MarkBox(b, s0, t0, w, kFineSide, &marked);
  }
  const int32_t at = static_cast<int32_t>(fine_.size());
  fine_at_[i * kGridSide + j] = at;
  fine_.resize(fine_.size() + kCells, static_cast<uint8_t>(CellState::kStraddles));
  // A piece with a sub-cell on the cell's side takes the state of the grid
  // cell across that side, if that one is no curve's (the kernel classified
  // its piece): no curve separates the two, and the kernel, asked here, would
  // answer the same (the premise of pieces, kFineSide). The exact trim is
  // checked against it as against a kernel answer. Pieces enclosed in the
  // cell, or beside cells the trim may cross, ask the kernel.
  ClassifyPieces(marked, kFineSide, fine_.data() + at, [&](int k, const std::vector<int>& piece) {
    const double s = s0 + (k / kFineSide + 0.5) * w, t = t0 + (k % kFineSide + 0.5) * w;
    const CellState across = StateAcross(i, j, piece);
    if (across == CellState::kStraddles) return CheckedKernelState(s, t);
    CheckExact(s, t, across);
    return across;
  });
}

inline void FaceTrim::EnsureGrid() const {
  // The flag first: std::call_once writes thread-locals on every call, a
  // cost the tree build's half a million Contains calls noticed.
  if (grid_ready_.load(std::memory_order_acquire)) return;
  std::call_once(grid_once_, [this] {
    BuildGrid();
    grid_ready_.store(true, std::memory_order_release);
  });
}

inline CellState FaceTrim::GridState(double s, double t) const {
  // floor(2048 s) / 16 = floor(128 s): both scalings are exact.
  constexpr int kSide = kGridSide * kFineSide;
  const int fi = std::clamp(static_cast<int>(s * kSide), 0, kSide - 1);
  const int fj = std::clamp(static_cast<int>(t * kSide), 0, kSide - 1);
  const int cell = (fi / kFineSide) * kGridSide + fj / kFineSide;
  CellState state = grid_[cell];
  if (state == CellState::kStraddles && fine_at_[cell] >= 0) {
    state = static_cast<CellState>(
        fine_[fine_at_[cell] + (fi % kFineSide) * kFineSide + fj % kFineSide]);
  }
  return state;
}

bool FaceTrim::Contains(double s, double t) const {
  if (!trimmed_) return true;
  EnsureGrid();
  switch (GridState(s, t)) {
    case CellState::kInside: return true;
    case CellState::kOutside: return false;
    case CellState::kStraddles: break;
  }
  return ContainsNearTrim(s, t);
}

bool FaceTrim::KeepsWhole(double s0, double s1, double t0, double t1) const {
  if (!trimmed_) return true;
  EnsureGrid();
  // Contains reads grid cell floor(128 s) (GridState, clamped), so the
  // closed cell's points read cells floor(128 s0) .. floor(128 s1).
  auto cell = [](double x) {
    return std::clamp(static_cast<int>(x * kGridSide), 0, kGridSide - 1);
  };
  for (int i = cell(s0); i <= cell(s1); ++i) {
    for (int j = cell(t0); j <= cell(t1); ++j) {
      if (grid_[i * kGridSide + j] != CellState::kInside) return false;
    }
  }
  return true;
}

void FaceTrim::ContainsMany(const double* s, const double* t, size_t n, uint8_t* inside) const {
  if (!trimmed_) {
    std::fill(inside, inside + n, uint8_t{1});
    return;
  }
  EnsureGrid();
  for (size_t i = 0; i < n; ++i) {
    const CellState state = GridState(s[i], t[i]);
    inside[i] = state == CellState::kStraddles ? ContainsNearTrim(s[i], t[i])
                                               : state == CellState::kInside;
  }
}

bool FaceTrim::ContainsNearTrim(double s, double t) const {
  if (exact_) {
    const LineCircleTrim::Side side = exact_->Classify(map_.U(s), map_.V(t));
    if (side != LineCircleTrim::Side::kUnsure) return side == LineCircleTrim::Side::kIn;
  }
  auto classifier = classifiers_.Take();
  try {
    return classifier->Perform(gp_Pnt2d(map_.U(s), map_.V(t))) != TopAbs_OUT;
  } catch (const Standard_Failure&) {
    return false;
  }
}

CellState FaceTrim::KernelState(double s, double t) const {
  auto classifier = classifiers_.Take();
  try {
    switch (classifier->Perform(gp_Pnt2d(map_.U(s), map_.V(t)))) {
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

CellState FaceTrim::Classify(double s0, double s1, double t0, double t1) const {
  if (!trimmed_) return CellState::kInside;
  if (CrossesBoundary({s0, s1, t0, t1})) return CellState::kStraddles;
  return KernelState(0.5 * (s0 + s1), 0.5 * (t0 + t1));
}

}  // namespace sfc::cad
