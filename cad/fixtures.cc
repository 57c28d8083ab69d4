#include "cad/fixtures.h"

#include <unistd.h>

#include <BRepAlgoAPI_Cut.hxx>
#include <BRepBuilderAPI_MakeVertex.hxx>
#include <BRepClass_FaceClassifier.hxx>
#include <BRepExtrema_DistShapeShape.hxx>
#include <BRepTools.hxx>
#include <ElCLib.hxx>
#include <GeomAPI_ProjectPointOnSurf.hxx>
#include <Geom_Surface.hxx>
#include <Precision.hxx>
#include <IGESControl_Reader.hxx>
#include <STEPControl_Reader.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <BRepBuilderAPI_MakeEdge.hxx>
#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepBuilderAPI_MakeWire.hxx>
#include <GeomAPI_Interpolate.hxx>
#include <Geom_BSplineCurve.hxx>
#include <TColgp_HArray1OfPnt.hxx>
#include <TopoDS_Wire.hxx>
#include <gp_Pln.hxx>
#include <BRepBuilderAPI_Transform.hxx>
#include <BRepFilletAPI_MakeFillet.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepPrimAPI_MakeCone.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <BRepPrimAPI_MakeSphere.hxx>
#include <BRep_Builder.hxx>
#include <BRep_Tool.hxx>
#include <IGESControl_Controller.hxx>
#include <IGESControl_Writer.hxx>
#include <STEPControl_Writer.hxx>
#include <Standard_Failure.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Compound.hxx>
#include <TopoDS_Edge.hxx>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <fstream>
#include <gp_Ax2.hxx>
#include <gp_Pnt.hxx>
#include <gp_Trsf.hxx>
#include <sstream>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "base/status_macros.h"
#include "cad/internal/kernel_setup.h"
#include "core/vector_math.h"

namespace sfc::cad::fixtures {
namespace {

// `shape` turned by 0.7 rad about (1, 2, 3), its geometry moved (no location).
TopoDS_Shape Tilted(const TopoDS_Shape& shape) {
  gp_Trsf turn;
  turn.SetRotation(gp_Ax1(gp_Pnt(1, 2, 3), gp_Dir(1, 2, 3)), 0.7);
  return BRepBuilderAPI_Transform(shape, turn, /*copy=*/true).Shape();
}

// kSplineHolePlate's hole: a periodic cubic B-spline through 40 points of
// r = 10 + 3 sin 7a.
Handle(Geom_BSplineCurve) SplineHole() {
  const int n = 40;
  Handle(TColgp_HArray1OfPnt) points = new TColgp_HArray1OfPnt(1, n);
  for (int i = 0; i < n; ++i) {
    // SLEEF's sines (core/vector_math.h): the same file on every machine.
    const double a = 2 * M_PI * i / n, r = 10 + 3 * math::SinCosOf(7 * a).sin;
    const math::SinCos t = math::SinCosOf(a);
    points->SetValue(i + 1, gp_Pnt(r * t.cos, r * t.sin, 0));
  }
  GeomAPI_Interpolate interpolate(points, /*periodic=*/true, 1e-9);
  interpolate.Perform();
  return interpolate.Curve();
}

TopoDS_Shape MakeSolid(Solid solid) {
  switch (solid) {
    case Solid::kSphere:
      return BRepPrimAPI_MakeSphere(gp_Pnt(0, 0, 0), kSphereRadius).Shape();
    case Solid::kCylinder:
      return BRepPrimAPI_MakeCylinder(kCylinderRadius, kCylinderHeight).Shape();
    case Solid::kBoxWithHole: {
      const TopoDS_Shape box = BRepPrimAPI_MakeBox(kBoxX, kBoxY, kBoxZ).Shape();
      BRepFilletAPI_MakeFillet fillet(box);
      for (TopExp_Explorer it(box, TopAbs_EDGE); it.More(); it.Next()) {
        const TopoDS_Edge& edge = TopoDS::Edge(it.Current());
        const gp_Pnt a = BRep_Tool::Pnt(TopExp::FirstVertex(edge));
        const gp_Pnt b = BRep_Tool::Pnt(TopExp::LastVertex(edge));
        if (a.X() == kBoxX && b.X() == kBoxX && a.Y() == kBoxY && b.Y() == kBoxY) {
          fillet.Add(kFilletRadius, edge);
        }
      }
      const TopoDS_Shape rounded = fillet.Shape();
      const TopoDS_Shape drill =
          BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(kBoxX / 2, kBoxY / 2, -1), gp::DZ()), kHoleRadius,
                                   kBoxZ + 2)
              .Shape();
      return BRepAlgoAPI_Cut(rounded, drill).Shape();
    }
    case Solid::kEdgeOnly:
      return BRepBuilderAPI_MakeEdge(gp_Pnt(0, 0, 0), gp_Pnt(kBoxX, 0, 0)).Shape();
    case Solid::kTiltedBoxWithHole:
      return Tilted(MakeSolid(Solid::kBoxWithHole));
    case Solid::kSplineHolePlate: {
      const gp_Pln plane(gp_Pnt(0, 0, 0), gp::DZ());
      BRepBuilderAPI_MakeFace face(plane, -20, 20, -20, 20);
      TopoDS_Wire hole = BRepBuilderAPI_MakeWire(BRepBuilderAPI_MakeEdge(SplineHole()).Edge());
      hole.Reverse();
      face.Add(hole);
      return face.Shape();
    }
    case Solid::kTiltedConeAndTorus: {
      // The base's circular edge rounded: the round between the cone and the
      // base's plane is a piece of a torus.
      const TopoDS_Shape cone = BRepPrimAPI_MakeCone(10, 4, 15).Shape();
      BRepFilletAPI_MakeFillet fillet(cone);
      for (TopExp_Explorer it(cone, TopAbs_EDGE); it.More(); it.Next()) {
        const TopoDS_Edge& edge = TopoDS::Edge(it.Current());
        if (!BRep_Tool::Degenerated(edge) && BRep_Tool::Pnt(TopExp::FirstVertex(edge)).Z() == 0)
          fillet.Add(2, edge);
      }
      return Tilted(fillet.Shape());
    }
  }
  return {};
}

absl::StatusOr<std::string> ReadBack(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return absl::InternalError(absl::StrCat("cannot read ", path));
  std::ostringstream out;
  out << in.rdbuf();
  return out.str();
}

}  // namespace

std::string SolidName(Solid solid) {
  switch (solid) {
    case Solid::kSphere:
      return "sphere";
    case Solid::kCylinder:
      return "cylinder";
    case Solid::kBoxWithHole:
      return "box_with_hole";
    case Solid::kEdgeOnly:
      return "edge_only";
    case Solid::kTiltedBoxWithHole:
      return "tilted_box_with_hole";
    case Solid::kTiltedConeAndTorus:
      return "tilted_cone_and_torus";
    case Solid::kSplineHolePlate:
      return "spline_hole_plate";
  }
  return "unknown";
}

absl::StatusOr<std::string> SolidBytes(Solid solid, ModelFormat format, int copies) {
  if (format == ModelFormat::kNurbs)
    return absl::InvalidArgumentError("solids are written as STEP or IGES");
  // The writers write files only; a private temporary one, removed after.
  std::error_code ignored;
  std::string path =
      (std::filesystem::temp_directory_path(ignored) / "sfc-fixture-XXXXXX").string();
  const int fd = mkstemp(path.data());
  if (fd < 0) return absl::InternalError("cannot create a temporary file");
  ::close(fd);
  struct Remove {
    std::string path;
    ~Remove() {
      std::error_code e;
      std::filesystem::remove(path, e);
    }
  } remove{path};
  SilenceKernelMessages();
  try {
    TopoDS_Shape shape = MakeSolid(solid);
    if (copies > 1) {
      // A row of 20 a line, 10 mm apart past the largest solid.
      TopoDS_Compound compound;
      BRep_Builder builder;
      builder.MakeCompound(compound);
      for (int i = 0; i < copies; ++i) {
        gp_Trsf move;
        move.SetTranslation(gp_Vec((kBoxX + 10) * (i % 20), (kBoxY + 10) * (i / 20), 0));
        builder.Add(compound, BRepBuilderAPI_Transform(shape, move, /*copy=*/true).Shape());
      }
      shape = compound;
    }
    bool ok = false;
    if (format == ModelFormat::kStep) {
      STEPControl_Writer writer;
      ok = writer.Transfer(shape, STEPControl_AsIs) == IFSelect_RetDone &&
           writer.Write(path.c_str()) == IFSelect_RetDone;
    } else {
      IGESControl_Controller::Init();
      IGESControl_Writer writer("MM", 1);  // 1: faces as B-rep solids (MSBO), not bare surfaces
      ok = writer.AddShape(shape);
      writer.ComputeModel();
      ok = ok && writer.Write(path.c_str());
    }
    if (!ok)
      return absl::InternalError(absl::StrCat("the kernel could not write ", SolidName(solid)));
  } catch (const Standard_Failure& e) {
    return absl::InternalError(
        absl::StrCat("the kernel failed writing ", SolidName(solid), ": ", e.GetMessageString()));
  }
  return ReadBack(path);
}

namespace {

// A STEP of planar faces on z = 0, each bounded by a POLY_LOOP through
// `loops[i]` (x, y), in one open shell of a surface model inside the product
// structure the reader takes as its root. Written by hand: the kernel's
// writer would not write degenerate loops.
std::string PolyLoopFacesStep(const std::vector<std::vector<std::pair<double, double>>>& loops) {
  std::string data;
  int id = 0;
  auto add = [&](const std::string& record) {
    absl::StrAppend(&data, "#", ++id, " = ", record, ";\n");
    return id;
  };
  auto real = [](double v) {  // a STEP REAL always has its decimal point: "1.", "1.E-05"
    std::string text = absl::StrFormat("%.17G", v);
    if (text.find('.') == std::string::npos)
      text.insert(std::min(text.find('E'), text.size()), ".");
    return text;
  };
  auto point = [&](double x, double y) {
    return add(absl::StrFormat("CARTESIAN_POINT('',(%s,%s,0.))", real(x), real(y)));
  };
  const int origin = point(0, 0);
  const int z = add("DIRECTION('',(0.,0.,1.))");
  const int x = add("DIRECTION('',(1.,0.,0.))");
  const int axes = add(absl::StrFormat("AXIS2_PLACEMENT_3D('',#%d,#%d,#%d)", origin, z, x));
  const int plane = add(absl::StrFormat("PLANE('',#%d)", axes));
  auto references = [](const std::vector<int>& ids) {  // 8 a line, as writers wrap them
    std::string list;
    for (size_t i = 0; i < ids.size(); ++i) {
      absl::StrAppend(&list, i == 0 ? "#" : i % 8 ? ",#" : ",\n  #", ids[i]);
    }
    return list;
  };
  std::vector<int> faces;
  auto face = [&](const std::vector<int>& points) {
    const int loop = add(absl::StrFormat("POLY_LOOP('',(%s))", references(points)));
    const int bound = add(absl::StrFormat("FACE_OUTER_BOUND('',#%d,.T.)", loop));
    faces.push_back(add(absl::StrFormat("FACE_SURFACE('',(#%d),#%d,.T.)", bound, plane)));
  };
  for (const auto& loop : loops) {
    std::vector<int> points;
    for (const auto& [px, py] : loop) points.push_back(point(px, py));
    face(points);
  }
  // The faces in an open shell of a surface model, and the product around
  // it that the reader takes as its root.
  const int shell = add(absl::StrFormat("OPEN_SHELL('',(%s))", references(faces)));
  const int surface_model = add(absl::StrFormat("SHELL_BASED_SURFACE_MODEL('',(#%d))", shell));
  const int mm = add("( LENGTH_UNIT() NAMED_UNIT(*) SI_UNIT(.MILLI.,.METRE.) )");
  const int radian = add("( NAMED_UNIT(*) PLANE_ANGLE_UNIT() SI_UNIT($,.RADIAN.) )");
  const int steradian = add("( NAMED_UNIT(*) SI_UNIT($,.STERADIAN.) SOLID_ANGLE_UNIT() )");
  const int uncertainty = add(absl::StrFormat(
      "UNCERTAINTY_MEASURE_WITH_UNIT(LENGTH_MEASURE(1.E-07),#%d,'distance_accuracy_value','')",
      mm));
  const int context = add(absl::StrFormat(
      "( GEOMETRIC_REPRESENTATION_CONTEXT(3) GLOBAL_UNCERTAINTY_ASSIGNED_CONTEXT((#%d)) "
      "GLOBAL_UNIT_ASSIGNED_CONTEXT((#%d,#%d,#%d)) REPRESENTATION_CONTEXT('','') )",
      uncertainty, mm, radian, steradian));
  const int representation = add(absl::StrFormat(
      "MANIFOLD_SURFACE_SHAPE_REPRESENTATION('',(#%d,#%d),#%d)", axes, surface_model, context));
  const int application =
      add("APPLICATION_CONTEXT('core data for automotive mechanical design processes')");
  const int product_context =
      add(absl::StrFormat("PRODUCT_CONTEXT('',#%d,'mechanical')", application));
  const int product =
      add(absl::StrFormat("PRODUCT('collinear','collinear','',(#%d))", product_context));
  const int formation = add(absl::StrFormat("PRODUCT_DEFINITION_FORMATION('','',#%d)", product));
  const int definition_context = add(
      absl::StrFormat("PRODUCT_DEFINITION_CONTEXT('part definition',#%d,'design')", application));
  const int definition = add(
      absl::StrFormat("PRODUCT_DEFINITION('design','',#%d,#%d)", formation, definition_context));
  const int shape = add(absl::StrFormat("PRODUCT_DEFINITION_SHAPE('','',#%d)", definition));
  add(absl::StrFormat("SHAPE_DEFINITION_REPRESENTATION(#%d,#%d)", shape, representation));
  return absl::StrCat(
      "ISO-10303-21;\nHEADER;\nFILE_DESCRIPTION((''),'2;1');\n"
      "FILE_NAME('','',(''),(''),'','','');\n"
      "FILE_SCHEMA(('AUTOMOTIVE_DESIGN { 1 0 10303 214 1 1 1 1 }'));\nENDSEC;\nDATA;\n",
      data, "ENDSEC;\nEND-ISO-10303-21;\n");
}

}  // namespace

std::string CollinearFacesStep(int collinear, bool with_square) {
  std::vector<std::vector<std::pair<double, double>>> loops;
  for (int k = 0; k < collinear; ++k) {
    const double a = (k + 1) / std::sqrt(2.0), step = 0.5 / std::sqrt(3.0);
    loops.push_back({{a, a}, {a + step, a + step}, {a + 2 * step, a + 2 * step}});
  }
  if (with_square)
    loops.push_back({{kSquareX, 0}, {kSquareX + 1, 0}, {kSquareX + 1, 1}, {kSquareX, 1}});
  return PolyLoopFacesStep(loops);
}

std::string PolygonFaceStep(int corners) {
  std::vector<std::pair<double, double>> loop;
  for (int k = 0; k < corners; ++k) {
    const math::SinCos t = math::SinCosOf(2 * M_PI * k / corners);
    loop.push_back({t.cos, t.sin});
  }
  return PolyLoopFacesStep({loop});
}

absl::StatusOr<double> MaxDistanceToFaces(const std::string& bytes, ModelFormat format,
                                          const std::vector<PointOnFace>& points) {
  TopoDS_Shape shape;
  if (format == ModelFormat::kStep) {
    STEPControl_Reader reader;
    std::istringstream in(bytes);
    if (reader.ReadStream("points.step", in) != IFSelect_RetDone) {
      return absl::InvalidArgumentError("the STEP reader refused the file");
    }
    reader.TransferRoots();
    shape = reader.OneShape();
  } else if (format == ModelFormat::kIges) {
    const std::string path = std::filesystem::temp_directory_path() /
                             absl::StrCat("sfc_distance_", getpid(), ".iges");
    std::ofstream(path, std::ios::binary) << bytes;
    IGESControl_Reader reader;
    const bool read = reader.ReadFile(path.c_str()) == IFSelect_RetDone;
    std::filesystem::remove(path);
    if (!read) return absl::InvalidArgumentError("the IGES reader refused the file");
    reader.TransferRoots();
    shape = reader.OneShape();
  } else {
    return absl::InvalidArgumentError("STEP or IGES only");
  }
  TopTools_IndexedMapOfShape faces;
  TopExp::MapShapes(shape, TopAbs_FACE, faces);
  double worst = 0;
  for (const PointOnFace& p : points) {
    if (p.face < 0 || p.face >= faces.Extent()) {
      return absl::InvalidArgumentError(absl::StrCat("face ", p.face, " is not in the file"));
    }
    // The nearest foot on the face's surface that the kernel's face
    // classifier puts inside the face, parameters taken into the face's
    // period first; else (no such foot) the distance to the face's boundary
    // by BRepExtrema (which on its own misses feet at another period).
    const TopoDS_Face& face = TopoDS::Face(faces(p.face + 1));
    const gp_Pnt point(p.x, p.y, p.z);
    const Handle(Geom_Surface) surface = BRep_Tool::Surface(face);
    double u0, u1, v0, v1;
    BRepTools::UVBounds(face, u0, u1, v0, v1);
    GeomAPI_ProjectPointOnSurf feet(point, surface);
    double best = std::numeric_limits<double>::infinity();
    for (int i = 1; feet.IsDone() && i <= feet.NbPoints(); ++i) {
      double u, v;
      feet.Parameters(i, u, v);
      if (surface->IsUPeriodic()) u = ElCLib::InPeriod(u, u0, u0 + surface->UPeriod());
      if (surface->IsVPeriodic()) v = ElCLib::InPeriod(v, v0, v0 + surface->VPeriod());
      BRepClass_FaceClassifier inside(face, gp_Pnt2d(u, v), Precision::PConfusion());
      if (inside.State() == TopAbs_IN || inside.State() == TopAbs_ON) {
        best = std::min(best, feet.Distance(i));
      }
    }
    if (!std::isfinite(best)) {
      BRepExtrema_DistShapeShape distance(BRepBuilderAPI_MakeVertex(point).Vertex(), face);
      if (!distance.IsDone()) return absl::InternalError("BRepExtrema found no distance");
      best = distance.Value();
    }
    worst = std::max(worst, best);
  }
  return worst;
}

std::string NurbsPatchText() {
  const double r = kPatchRadius, h = kPatchHeight, w = std::sqrt(0.5);
  std::string text =
      "sfcsampler-nurbs 1\n"
      "# a quarter cylinder: an exact rational quadratic arc in u, a line in v\n"
      "degree 2 1\n"
      "count 3 2\n"
      "knots_u 0 0 0 1 1 1\n"
      "knots_v 0 0 1 1\n";
  const double arc[3][3] = {{r, 0, 1}, {r, r, w}, {0, r, 1}};
  for (const auto& p : arc) {
    for (double z : {0.0, h}) {
      // Homogeneous weights multiply nothing here: poles are Cartesian.
      absl::StrAppendFormat(&text, "pole %.17g %.17g %.17g %.17g\n", p[0], p[1], z, p[2]);
    }
  }
  return text;
}

std::vector<std::pair<double, double>> SplineHolePoints(int n) {
  const Handle(Geom_BSplineCurve) curve = SplineHole();
  const double a = curve->FirstParameter(), b = curve->LastParameter();
  std::vector<std::pair<double, double>> out;
  for (int i = 0; i < n; ++i) {
    const gp_Pnt p = curve->Value(a + (b - a) * i / n);
    out.emplace_back(p.X(), p.Y());
  }
  return out;
}

absl::StatusOr<std::vector<std::string>> WriteAll(const std::string& dir) {
  std::vector<std::string> written;
  for (Solid solid : {Solid::kSphere, Solid::kCylinder, Solid::kBoxWithHole}) {
    for (ModelFormat format : {ModelFormat::kStep, ModelFormat::kIges}) {
      ASSIGN_OR_RETURN(std::string bytes, SolidBytes(solid, format));
      const std::string path =
          absl::StrCat(dir, "/", SolidName(solid), ".", std::string(ModelFormatName(format)));
      std::ofstream(path, std::ios::binary) << bytes;
      written.push_back(path);
    }
  }
  const std::string path = absl::StrCat(dir, "/quarter_cylinder.nurbs");
  std::ofstream(path) << NurbsPatchText();
  written.push_back(path);
  return written;
}

}  // namespace sfc::cad::fixtures
