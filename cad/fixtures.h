// Test models the project makes itself with OpenCASCADE (no binaries in the
// repository): a sphere, a cylinder, and a box with a fillet and a through
// hole, as STEP and IGES; and a NURBS patch in our text format. Their sizes
// are constants here so tests can compare with exact formulas.
//
// Thread-safety: the writers share the kernel's global state; call from one
// thread at a time.
#ifndef SFCSAMPLER_CAD_FIXTURES_H_
#define SFCSAMPLER_CAD_FIXTURES_H_

#include <string>
#include <utility>
#include <vector>

#include "absl/status/statusor.h"
#include "cad/load.h"

namespace sfc::cad::fixtures {

// A sphere of radius kSphereRadius about the origin.
inline constexpr double kSphereRadius = 10;
// A solid cylinder of radius kCylinderRadius and height kCylinderHeight on
// the z axis, base at z = 0.
inline constexpr double kCylinderRadius = 5;
inline constexpr double kCylinderHeight = 20;
// The box [0,kBoxX]x[0,kBoxY]x[0,kBoxZ], its vertical edge at (kBoxX, kBoxY)
// rounded with radius kFilletRadius, and a hole of radius kHoleRadius along z
// through (kBoxX/2, kBoxY/2).
inline constexpr double kBoxX = 40, kBoxY = 30, kBoxZ = 20;
inline constexpr double kFilletRadius = 3;
inline constexpr double kHoleRadius = 5;
// The NURBS patch: a quarter of a cylinder of radius kPatchRadius and height
// kPatchHeight (an exact rational quadratic arc in u, linear in v), area
// pi/2 kPatchRadius kPatchHeight.
inline constexpr double kPatchRadius = 2;
inline constexpr double kPatchHeight = 3;

// kEdgeOnly is a single straight edge and no face (a model without faces,
// for the error); WriteAll leaves it out.
// kTiltedBoxWithHole is kBoxWithHole turned by 0.7 rad about (1, 2, 3), its
// geometry moved (no location): planes and cylinders whose axes are not the
// coordinate axes.
// kTiltedConeAndTorus is a truncated cone (radii 10 and 4, height 15) whose
// base edge is rounded (radius 2: a piece of a torus), turned the same way:
// cones and tori.
// kSplineHolePlate is one planar face, the square [-20, 20]^2 at z = 0, with
// a hole bounded by a periodic cubic B-spline through 40 points of the wavy
// circle r = 10 + 3 sin 7a: a trim that is neither a line nor a circle.
enum class Solid {
  kSphere, kCylinder, kBoxWithHole, kEdgeOnly, kTiltedBoxWithHole, kTiltedConeAndTorus,
  kSplineHolePlate
};

// Points along kSplineHolePlate's hole (x, y), `n` of them evenly in its
// parameter, from the same curve.
std::vector<std::pair<double, double>> SplineHolePoints(int n);

// "sphere", "cylinder", "box_with_hole", "edge_only".
std::string SolidName(Solid solid);

// The solid written as STEP or IGES (ModelFormat::kStep or kIges), as bytes;
// `copies` > 1 writes that many copies side by side (a large model: 400
// boxes with a hole make a 7 MB STEP file). INVALID_ARGUMENT for kNurbs;
// INTERNAL if the kernel fails.
absl::StatusOr<std::string> SolidBytes(Solid solid, ModelFormat format, int copies = 1);

// The quarter-cylinder NURBS patch in our format (docs/NURBS_FORMAT.md).
std::string NurbsPatchText();

// A hand-written STEP of planar FACE_SURFACEs on z = 0 in one open shell
// (issue 37): `collinear` faces each bounded by a POLY_LOOP of three
// collinear points on the line x = y (no area; the k-th starts at
// (k+1)/sqrt(2) and is 1/sqrt(3) long), then, when `with_square`, the unit
// square [kSquareX, kSquareX + 1] x [0, 1] (area 1). The kernel takes
// about 2 ms and 900 KB a face to read them (1 000 faces: a 340 KB file,
// 2 s of CPU, 0.9 GB).
inline constexpr double kSquareX = 2.5;
std::string CollinearFacesStep(int collinear, bool with_square);

// A STEP of one planar face bounded by a POLY_LOOP of `corners` points on
// the unit circle: a valid model the kernel reads in time that grows like
// corners^2.7 and little memory (measured with OCC 7.6, sfcsampler-model-check
// alone: 2 000 corners 2.0 s of CPU and 36 MB; 6 000 corners, 487 KB, 53 s
// and 44 MB; 8 000 corners, 650 KB, 116 s and 47 MB).
// The hostile parse of the isolation test and bench/parse_isolation.py.
std::string PolygonFaceStep(int corners);

// A point with the index of the face it claims to lie on.
struct PointOnFace {
  int face = 0;  // in the file's order (Face::index())
  double x = 0, y = 0, z = 0;
};

// The largest distance from a point to its trimmed face, measured
// independently of the sampler: the STEP or IGES `bytes` read again by the
// kernel's reader, faces in TopExp::MapShapes order; the nearest foot on the
// face's surface (GeomAPI_ProjectPointOnSurf) that the kernel's own face
// classifier (BRepClass_FaceClassifier, not the one the sampler uses) puts
// inside, else BRepExtrema's distance to the face. No evaluation, trim or
// closed form of ours. INVALID_ARGUMENT for a face index out of range.
absl::StatusOr<double> MaxDistanceToFaces(const std::string& bytes, ModelFormat format,
                                          const std::vector<PointOnFace>& points);

// Writes every fixture into `dir` (which must exist): sphere.step,
// sphere.iges, cylinder.step, ..., box_with_hole.iges, quarter_cylinder.nurbs.
// Returns the paths written.
absl::StatusOr<std::vector<std::string>> WriteAll(const std::string& dir);

}  // namespace sfc::cad::fixtures

#endif  // SFCSAMPLER_CAD_FIXTURES_H_
