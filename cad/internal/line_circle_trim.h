// Internal to cad/: the trim of a face whose p-curves are all lines and
// circles, classified exactly in the face's native (U, V), without the kernel.
//
// A point farther than `band` from every p-curve is inside the face exactly
// when a ray from it, along +U, crosses the p-curves an odd number of times
// (the Jordan curve theorem: the wires are closed loops in (U, V)). Points
// within the band of a curve, rays that pass within it of an edge's end or
// touch a circle, are left to the kernel (kUnsure): the kernel decides what
// is on the trim. Away from the curves the kernel's classifier answers the
// same truth (cad/internal/occ_face.h, FaceTrim::kFineSide), but a point
// near a curve costs it an exact classification with its set-up (~10 us: the
// STEP box's trimmed faces asked it ~1 500 times for 10^6 samples).
//
// Thread-safety: immutable after Extract; thread-safe.
#ifndef SFCSAMPLER_CAD_INTERNAL_LINE_CIRCLE_TRIM_H_
#define SFCSAMPLER_CAD_INTERNAL_LINE_CIRCLE_TRIM_H_

#include <TopoDS_Face.hxx>

#include <optional>
#include <vector>

namespace sfc::cad {

class LineCircleTrim {
 public:
  enum class Side { kIn, kOut, kUnsure };

  // The face's trim, when every edge has a p-curve that is a line or a
  // circle and is oriented forward or reversed (no internal or external
  // edges); nullopt otherwise. `band` (> 0, native units) is how far from a
  // curve the answer is left to the kernel.
  static std::optional<LineCircleTrim> Extract(const TopoDS_Face& face, double band);

  Side Classify(double u, double v) const;

 private:
  struct Segment {
    double u0, v0, u1, v1;
  };
  // A circle's arc from S through M to E: the points of the circle on M's
  // side of the chord S E (every point when `full`).
  struct Arc {
    double cu, cv, r;
    double su, sv, eu, ev, mu, mv;
    bool full;
  };

  std::vector<Segment> segments_;
  std::vector<Arc> arcs_;
  double band_ = 0;
};

}  // namespace sfc::cad

#endif  // SFCSAMPLER_CAD_INTERNAL_LINE_CIRCLE_TRIM_H_
