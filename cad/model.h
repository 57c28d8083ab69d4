// A CAD model: the faces of a STEP or IGES file, or one NURBS patch, each a
// parametric surface over the unit square with a trim classifier.
//
// Every face is wrapped as our own sfc::Surface (core/surface.h), evaluated by
// OpenCASCADE with exact first and second derivatives; the kernel's types
// never appear in this header (as Gmsh wraps each TopoDS_Face in its OCCFace). The face's
// parameter box [u0,u1]x[v0,v1] is mapped linearly onto the unit square, with
// u reversed for a face whose orientation is reversed, so that fu x fv points
// out of the solid.
//
// The trim: a face is the part of its surface inside its wires. Contains()
// classifies one unit-square point, Classify() a parameter cell. The sampler
// keeps one curve tree per face and runs one curve through all faces in
// curve_order(); equalisation over the model weighs faces by trimmed area x
// density (issue 11).
//
// Thread-safety: a Model is immutable after Load(); every const method of
// Model, Face and the faces' surfaces may be called from many threads at once
// (each thread evaluates on its own copy of the kernel's adaptors).
#ifndef SFCSAMPLER_CAD_MODEL_H_
#define SFCSAMPLER_CAD_MODEL_H_

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "absl/strings/string_view.h"
#include "core/surface.h"
#include "core/types/vec3.h"

namespace sfc::cad {

// The kernel's kind of underlying surface of a face.
enum class FaceType {
  kPlane,
  kCylinder,
  kCone,
  kSphere,
  kTorus,
  kBSpline,
  kBezier,
  kRevolution,
  kExtrusion,
  kOffset,
  kOther,
};

// "plane", "cylinder", ..., "other".
absl::string_view FaceTypeName(FaceType type);

// A face's native parameter box (the kernel's UV bounds of its wires).
struct ParameterBox {
  double u0 = 0, u1 = 0, v0 = 0, v1 = 0;
};

// Where a parameter cell lies relative to a face's trimmed region.
enum class CellState {
  kInside,     // every point of the cell is in the face (up to the tolerance)
  kOutside,    // no point of the cell is in the face
  kStraddles,  // the trim boundary may cross the cell: refine it
};

class FaceTrim;  // internal: the kernel's classifier and the boundary boxes

// One face of a model. Immutable; shared by the model's copies.
class Face {
 public:
  Face(int index, FaceType type, double area, ParameterBox box, bool reversed, Vec3 centroid,
       bool trimmed, std::shared_ptr<const Surface> surface, std::shared_ptr<const FaceTrim> trim);

  // Position in the file's order of faces, 0-based.
  int index() const { return index_; }
  FaceType type() const { return type_; }
  // Area of the trimmed face (the kernel's surface integral over the face,
  // BRepGProp), in the model's length unit squared; 0 for a face thinner on
  // average than the kernel's tolerance (area <= Precision::Confusion() x its
  // bounding box's diagonal), which takes no samples.
  double area() const { return area_; }
  // The native parameter box mapped onto the unit square.
  const ParameterBox& parameter_box() const { return box_; }
  // True if the face's orientation is reversed (u is then mapped from u1 to
  // u0 so that the normal points outward).
  bool reversed() const { return reversed_; }
  // Centre of mass of the trimmed face.
  const Vec3& centroid() const { return centroid_; }
  // False if the trimmed region is (within the tolerance) the whole parameter
  // box, so Classify() never answers kOutside or kStraddles.
  bool trimmed() const { return trimmed_; }

  // The face as a parametric surface over the unit square: Point, and Jet
  // with the kernel's exact first and second derivatives.
  const Surface& surface() const { return *surface_; }
  // True when the surface is evaluated from its closed form (a plane,
  // cylinder, cone, sphere or torus without a transformation: the kernel's
  // formulas without its adaptors, with SLEEF's sines and cosines, so the
  // same bits on every machine; checked against the kernel within a few ulp
  // at load), false when through the kernel (whose elementary functions are
  // the C library's).
  bool closed_form() const;
  std::shared_ptr<const Surface> shared_surface() const { return surface_; }

  // True if the unit-square point (s, t) lies in the trimmed face; points on
  // the trim boundary (within the tolerance) count as inside. Fast away from
  // the trim: a 128 x 128 grid of Classify() answers, made on first use, with
  // 16 x 16 sub-cells in each cell the boundary may cross, leaves the kernel
  // only the points within ~1/2048 of the boundary.
  // REQUIRES: (s, t) in [0,1]^2.
  bool Contains(double s, double t) const;
  // inside[i] = Contains(s[i], t[i]) for i < n (1 or 0), one call for a batch.
  void ContainsMany(const double* s, const double* t, size_t n, uint8_t* inside) const;
  // True when Contains answers true at every point of the closed cell
  // [s0,s1]x[t0,t1] from the grid alone (every grid cell it meets is inside
  // the trim); false may also mean the grid cannot tell. REQUIRES: 0 <= s0
  // <= s1 <= 1, same for t.
  bool KeepsWhole(double s0, double s1, double t0, double t1) const;
  // The side of that grid's cells in the unit square (1/128).
  static double TrimGridCell();

  // State of the cell [s0,s1]x[t0,t1] of the unit square. Conservative: only
  // kInside or kOutside when no trim curve can enter the cell (the curves are
  // enclosed in boxes of at most ~1/2048 of the square; a cell that close to
  // the boundary stays kStraddles). REQUIRES: 0 <= s0 <= s1 <= 1, same for t.
  CellState Classify(double s0, double s1, double t0, double t1) const;

  // A lower bound on the distance in the unit square from (s, t) to the trim
  // curves (with the tolerance): points nearer than it, joined to (s, t) by a
  // segment, have its Contains() answer. 0 when it cannot tell.
  double Clearance(double s, double t) const;

 private:
  int index_;
  FaceType type_;
  double area_;
  ParameterBox box_;
  bool reversed_;
  Vec3 centroid_;
  bool trimmed_;
  std::shared_ptr<const Surface> surface_;
  std::shared_ptr<const FaceTrim> trim_;
};

class Model {
 public:
  Model(std::string name, std::vector<Face> faces);

  // The name given to Load (a file name, for messages).
  const std::string& name() const { return name_; }
  // Faces in the file's order (the order of the kernel's face map).
  const std::vector<Face>& faces() const { return faces_; }
  // Sum of the faces' trimmed areas.
  double total_area() const { return total_area_; }
  // The faces' indices in the order one curve visits them: the 3D Hilbert
  // order of their centroids (cad/face_order.h), so consecutive faces are
  // close in space, then the faces without area in file order. A
  // permutation of 0..faces().size()-1.
  const std::vector<int>& curve_order() const { return curve_order_; }

 private:
  std::string name_;
  std::vector<Face> faces_;
  double total_area_ = 0;
  std::vector<int> curve_order_;
};

// A human-readable table of the model: per face its index, type, trimmed
// area, parameter box, orientation and whether it is trimmed; then the total
// area and the curve order. For `sfcsampler inspect`.
std::string DescribeModel(const Model& model);

}  // namespace sfc::cad

#endif  // SFCSAMPLER_CAD_MODEL_H_
