#include "cad/internal/line_circle_trim.h"

#include <BRep_Tool.hxx>
#include <Geom2dAdaptor_Curve.hxx>
#include <Geom2d_Curve.hxx>
#include <Standard_Failure.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Edge.hxx>
#include <gp_Circ2d.hxx>
#include <gp_Pnt2d.hxx>

#include <cmath>

namespace sfc::cad {
namespace {

// The length of (a, b) by sqrt (correctly rounded under IEEE 754, so the same
// bits on every machine, unlike the C library's hypot; parameters are far
// from overflow).
double Length(double a, double b) { return std::sqrt(a * a + b * b); }

// The distance from (u, v) to the segment from (u0, v0) to (u1, v1).
double SegmentDistance(double u0, double v0, double u1, double v1, double u, double v) {
  const double du = u1 - u0, dv = v1 - v0;
  const double length2 = du * du + dv * dv;
  double f = length2 > 0 ? ((u - u0) * du + (v - v0) * dv) / length2 : 0.0;
  f = f < 0 ? 0.0 : f > 1 ? 1.0 : f;
  return Length(u - (u0 + f * du), v - (v0 + f * dv));
}

double Cross(double au, double av, double bu, double bv) { return au * bv - av * bu; }

}  // namespace

std::optional<LineCircleTrim> LineCircleTrim::Extract(const TopoDS_Face& face, double band) {
  LineCircleTrim trim;
  trim.band_ = band;
  try {
    for (TopExp_Explorer it(face, TopAbs_EDGE); it.More(); it.Next()) {
      const TopoDS_Edge& edge = TopoDS::Edge(it.Current());
      if (edge.Orientation() != TopAbs_FORWARD && edge.Orientation() != TopAbs_REVERSED) {
        return std::nullopt;
      }
      double first = 0, last = 0;
      Handle(Geom2d_Curve) pcurve = BRep_Tool::CurveOnSurface(edge, face, first, last);
      if (pcurve.IsNull()) return std::nullopt;
      const Geom2dAdaptor_Curve curve(pcurve, first, last);
      const gp_Pnt2d s = curve.Value(first), e = curve.Value(last);
      if (curve.GetType() == GeomAbs_Line) {
        trim.segments_.push_back({s.X(), s.Y(), e.X(), e.Y()});
      } else if (curve.GetType() == GeomAbs_Circle) {
        const gp_Circ2d circle = curve.Circle();
        const gp_Pnt2d m = curve.Value(0.5 * (first + last));
        Arc arc{circle.Location().X(), circle.Location().Y(), circle.Radius(),
                s.X(), s.Y(), e.X(), e.Y(), m.X(), m.Y(), false};
        // Ends that meet make a whole circle only if the arc turns more than
        // half way round (its parameter is the angle): a short arc of a large
        // circle has close ends too.
        arc.full = Length(e.X() - s.X(), e.Y() - s.Y()) <= band && last - first > M_PI;
        trim.arcs_.push_back(arc);
      } else {
        return std::nullopt;
      }
    }
  } catch (const Standard_Failure&) {
    return std::nullopt;
  }
  if (trim.segments_.empty() && trim.arcs_.empty()) return std::nullopt;
  return trim;
}

LineCircleTrim::Side LineCircleTrim::Classify(double u, double v) const {
  int crossings = 0;
  for (const Segment& g : segments_) {
    if (SegmentDistance(g.u0, g.v0, g.u1, g.v1, u, v) <= band_) return Side::kUnsure;
    // A ray through (or beside) an end: which side counts it is the kernel's.
    if (std::fabs(v - g.v0) <= band_ || std::fabs(v - g.v1) <= band_) return Side::kUnsure;
    if ((g.v0 > v) != (g.v1 > v)) {
      const double x = g.u0 + (v - g.v0) * (g.u1 - g.u0) / (g.v1 - g.v0);
      if (x > u) ++crossings;
    }
  }
  for (const Arc& a : arcs_) {
    const double du = u - a.cu, dv = v - a.cv;
    // Near the circle (so near the arc, or not: either way the kernel's).
    if (std::fabs(Length(du, dv) - a.r) <= band_) return Side::kUnsure;
    if (!a.full && (std::fabs(v - a.sv) <= band_ || std::fabs(v - a.ev) <= band_)) {
      return Side::kUnsure;
    }
    if (std::fabs(std::fabs(dv) - a.r) <= band_) return Side::kUnsure;  // the ray touches it
    const double disc = a.r * a.r - dv * dv;
    if (!(disc > 0)) continue;
    const double w = std::sqrt(disc);
    // The arc's side of its chord S E is M's side.
    const double mid = Cross(a.eu - a.su, a.ev - a.sv, a.mu - a.su, a.mv - a.sv);
    for (const double x : {a.cu - w, a.cu + w}) {
      if (!(x > u)) continue;
      if (!a.full) {
        const double side = Cross(a.eu - a.su, a.ev - a.sv, x - a.su, v - a.sv);
        if (side == 0) return Side::kUnsure;
        if ((side > 0) != (mid > 0)) continue;
      }
      ++crossings;
    }
  }
  return crossings % 2 == 1 ? Side::kIn : Side::kOut;
}

}  // namespace sfc::cad
