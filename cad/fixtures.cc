#include "cad/fixtures.h"

#include <unistd.h>

#include <BRepAlgoAPI_Cut.hxx>
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
#include <cmath>
#include <filesystem>
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
    const double a = 2 * M_PI * i / n, r = 10 + 3 * std::sin(7 * a);
    points->SetValue(i + 1, gp_Pnt(r * std::cos(a), r * std::sin(a), 0));
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
          absl::StrCat(dir, "/", SolidName(solid), ".", ModelFormatName(format));
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
