#include "cad/load.h"

// OCC_CATCH_SIGNALS converts faults only with this defined (as Debian's
// OpenCASCADE was built); before any kernel header.
#ifndef OCC_CONVERT_SIGNALS
#define OCC_CONVERT_SIGNALS
#endif
#include <fcntl.h>
#include <unistd.h>

#include <BRepAdaptor_Surface.hxx>
#include <BRepBndLib.hxx>
#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepGProp.hxx>
#include <BRepLib.hxx>
#include <BRepTools.hxx>
#include <BinTools.hxx>
#include <Bnd_Box.hxx>
#include <GProp_GProps.hxx>
#include <Geom_BSplineSurface.hxx>
#include <IGESControl_Reader.hxx>
#include <IGESData_IGESEntity.hxx>
#include <Message_ProgressIndicator.hxx>
#include <Message_ProgressScope.hxx>
#include <Interface_Check.hxx>
#include <Interface_CheckIterator.hxx>
#include <Interface_InterfaceModel.hxx>
#include <StepShape_Face.hxx>
#include <TCollection_HAsciiString.hxx>
#include <TransferBRep.hxx>
#include <Transfer_TransientProcess.hxx>
#include <XSControl_TransferReader.hxx>
#include <XSControl_WorkSession.hxx>
#include <Precision.hxx>
#include <STEPControl_Reader.hxx>
#include <Standard_ErrorHandler.hxx>
#include <Standard_Failure.hxx>
#include <TColStd_Array1OfInteger.hxx>
#include <TColStd_Array1OfReal.hxx>
#include <TColStd_Array2OfReal.hxx>
#include <TColgp_Array2OfPnt.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Shape.hxx>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <new>
#include <optional>
#include <sstream>
#include <string>
#include <unordered_set>
#include <vector>

#include "absl/status/status.h"
#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "absl/synchronization/mutex.h"
#include "base/echo.h"
#include "base/status_macros.h"
#include "cad/internal/kernel_setup.h"
#include "cad/internal/occ_face.h"
#include "cad/nurbs_patch.h"
#include "cad/preflight.h"
#include "request/model_files.h"

namespace sfc::cad {
namespace {

// "step", "iges" or "nurbs" (request/model_spec.h's names), for messages.
std::string FormatName(ModelFormat format) { return std::string(ModelFormatName(format)); }

// The STEP and IGES readers share the kernel's global parameters
// (Interface_Static) and its messenger; one load at a time.
absl::Mutex g_reader_mutex;

absl::Status Invalid(ModelFormat format, absl::string_view name, absl::string_view what) {
  return absl::InvalidArgumentError(
      absl::StrCat(absl::AsciiStrToUpper(FormatName(format)), " file ", name, ": ", what));
}

// The text must open with the ISO 10303-21 header and end with its trailer:
// a file cut short (an interrupted upload) lacks the trailer.
absl::Status CheckStepFraming(absl::string_view bytes, absl::string_view name) {
  absl::string_view text = absl::StripAsciiWhitespace(bytes);
  if (!absl::StartsWith(text, "ISO-10303-21;")) {
    return Invalid(ModelFormat::kStep, name,
                   "not a STEP file (it does not start with 'ISO-10303-21;')");
  }
  if (!absl::EndsWith(text, "END-ISO-10303-21;")) {
    return Invalid(ModelFormat::kStep, name,
                   "truncated: it does not end with 'END-ISO-10303-21;' (was the file cut short?)");
  }
  return absl::OkStatus();
}

// IGES is 80-column records with the section letter in column 73; a complete
// file starts with S or G and ends with its single Terminate (T) record.
absl::Status CheckIgesFraming(absl::string_view bytes, absl::string_view name) {
  std::vector<absl::string_view> lines = absl::StrSplit(bytes, '\n', absl::SkipWhitespace());
  auto section = [](absl::string_view line) {
    line = absl::StripTrailingAsciiWhitespace(line);
    return line.size() >= 73 ? line[72] : '\0';
  };
  if (lines.empty() || (section(lines.front()) != 'S' && section(lines.front()) != 'G' &&
                        section(lines.front()) != 'F' && section(lines.front()) != 'C')) {
    return Invalid(ModelFormat::kIges, name, "not an IGES file (no Start section in column 73)");
  }
  if (section(lines.back()) != 'T') {
    return Invalid(
        ModelFormat::kIges, name,
        "truncated: the last record is not the Terminate section (was the file cut short?)");
  }
  return absl::OkStatus();
}

// A private temporary file holding bytes, deleted when this goes.
class TempFile {
 public:
  ~TempFile() {
    if (!path_.empty()) std::filesystem::remove(path_, ignored_);
  }
  absl::Status Write(absl::string_view bytes) {
    std::string pattern =
        (std::filesystem::temp_directory_path(ignored_) / "sfc-cad-XXXXXX.igs").string();
    const int fd = mkstemps(pattern.data(), 4);  // mode 0600
    if (fd < 0)
      return absl::InternalError(absl::StrCat("cannot create a temporary file in ", pattern));
    path_ = pattern;
    size_t done = 0;
    while (done < bytes.size()) {
      const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
      if (n <= 0) {
        ::close(fd);
        return absl::InternalError(absl::StrCat("cannot write the temporary file ", path_));
      }
      done += static_cast<size_t>(n);
    }
    if (::close(fd) != 0)
      return absl::InternalError(absl::StrCat("cannot close the temporary file ", path_));
    return absl::OkStatus();
  }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  std::error_code ignored_;
};

// OpenCASCADE's progress indicator as our stop check: the kernel's
// algorithms poll UserBreak() through their Message_ProgressScope and return
// early when it says so. The status that stopped it is kept.
class StopIndicator final : public Message_ProgressIndicator {
 public:
  explicit StopIndicator(std::function<absl::Status()> check) : check_(std::move(check)) {}
  Standard_Boolean UserBreak() override {
    if (!check_) return Standard_False;
    absl::Status s = check_();
    if (s.ok()) return Standard_False;
    absl::MutexLock lock(&mu_);
    if (status_.ok()) status_ = std::move(s);
    return Standard_True;
  }
  void Show(const Message_ProgressScope&, const Standard_Boolean) override {}
  absl::Status status() {
    absl::MutexLock lock(&mu_);
    return status_;
  }

 private:
  const std::function<absl::Status()> check_;
  absl::Mutex mu_;
  absl::Status status_ ABSL_GUARDED_BY(mu_);
};

// options.check's status now (OK when there is none).
absl::Status Checked(const LoadOptions& options) {
  return options.check ? options.check() : absl::OkStatus();
}

// The first fail the reader reported while loading the file (`load`) or
// transferring it, as "LABEL: message", clipped; "" when none.
std::string FirstFail(const Handle(Interface_InterfaceModel) & model,
                      const Interface_CheckIterator& checks) {
  for (checks.Start(); checks.More(); checks.Next()) {
    const Handle(Interface_Check)& check = checks.Value();
    if (check.IsNull() || !check->HasFailed()) continue;
    std::string where = "the file";
    if (check->HasEntity() && !model.IsNull() && model->Number(check->Entity()) > 0) {
      where = model->StringLabel(check->Entity())->ToCString();
    }
    return absl::StrCat(Echo(where, 24), ": ", Echo(check->CFail(1), kMaxEcho));
  }
  return "";
}

// Nothing lost silently: every face entity the preflight found in the file
// (census) must have become a face, and the reader must report no fail while
// loading the file. Missing faces are named (the first few).
absl::Status CheckTransfer(XSControl_Reader& reader, const ModelCensus& census, ModelFormat format,
                           absl::string_view name) {
  const Handle(XSControl_WorkSession) ws = reader.WS();
  const Handle(Interface_InterfaceModel) model = ws->Model();
  const Handle(Transfer_TransientProcess) process = ws->TransferReader()->TransientProcess();
  if (model.IsNull() || model->NbEntities() == 0) {
    return Invalid(format, name, "empty model: it has no entities");
  }
  // Labels of the face entities that became faces: "#12" (STEP), "D37" (IGES).
  std::unordered_set<std::string> transferred;
  const bool step = format == ModelFormat::kStep;
  for (int i = 1; !model.IsNull() && i <= model->NbEntities(); ++i) {
    const Handle(Standard_Transient) entity = model->Value(i);
    bool face = false;
    if (step) {
      face = entity->IsKind(STANDARD_TYPE(StepShape_Face));
    } else if (auto iges = Handle(IGESData_IGESEntity)::DownCast(entity); !iges.IsNull()) {
      face = true;  // any kind: surfaces too become faces
    }
    if (!face || process.IsNull()) continue;
    const TopoDS_Shape shape = TransferBRep::ShapeResult(process, entity);
    if (!shape.IsNull() && shape.ShapeType() == TopAbs_FACE) {
      transferred.insert(model->StringLabel(entity)->ToCString());
    }
  }
  std::vector<std::string> missing;
  for (size_t i = 0; i < census.faces.size(); ++i) {
    const std::string label = absl::StrCat(step ? "#" : "D", census.face_ids[i]);
    if (transferred.count(label) == 0) missing.push_back(census.faces[i]);
  }
  const std::string load_fail = FirstFail(model, ws->ModelCheckList());
  if (missing.empty()) {
    if (load_fail.empty()) return absl::OkStatus();
    return Invalid(format, name,
                   absl::StrCat("the reader found errors in it (first: ", load_fail,
                                "); fix or re-export the file"));
  }
  constexpr size_t kNamed = 5;
  std::string named;
  for (size_t i = 0; i < std::min(missing.size(), kNamed); ++i) {
    absl::StrAppend(&named, i ? ", " : "", Echo(missing[i], 40));
  }
  if (missing.size() > kNamed) absl::StrAppend(&named, ", ...");
  const std::string fail = !load_fail.empty() ? load_fail
                           : process.IsNull()
                               ? ""
                               : FirstFail(model, process->CheckList(Standard_False));
  return Invalid(
      format, name,
      absl::StrCat(missing.size(), " of its ", census.faces.size(),
                   " face entities did not become faces (", named, ")",
                   fail.empty() ? "" : absl::StrCat("; the reader said ", fail),
                   "; a dangling #reference or a damaged entity? fix or re-export the file"));
}

// REQUIRES: PreflightStep passed and gave `census`.
absl::StatusOr<TopoDS_Shape> ReadStep(absl::string_view bytes, const ModelCensus& census,
                                      absl::string_view name, const LoadOptions& options) {
  STEPControl_Reader reader;
  std::istringstream stream{std::string(bytes)};
  const IFSelect_ReturnStatus status = reader.ReadStream("upload.step", stream);
  if (status == IFSelect_RetVoid)
    return Invalid(ModelFormat::kStep, name, "empty model: it has no entities");
  if (status != IFSelect_RetDone) {
    return Invalid(ModelFormat::kStep, name,
                   "the STEP reader rejected it (syntax or structure errors)");
  }
  RETURN_IF_ERROR(Checked(options));
  Handle(StopIndicator) progress = new StopIndicator(options.check);
  reader.TransferRoots(progress->Start());
  RETURN_IF_ERROR(progress->status());
  RETURN_IF_ERROR(CheckTransfer(reader, census, ModelFormat::kStep, name));
  return reader.OneShape();
}

// Reads the IGES file at `path`, the private copy Load made of the bytes.
// REQUIRES: PreflightIges passed and gave `census`.
absl::StatusOr<TopoDS_Shape> ReadIges(const std::string& path, const ModelCensus& census,
                                      absl::string_view name, const LoadOptions& options) {
  IGESControl_Reader reader;
  const IFSelect_ReturnStatus status = reader.ReadFile(path.c_str());
  if (status == IFSelect_RetVoid)
    return Invalid(ModelFormat::kIges, name, "empty model: it has no entities");
  if (status != IFSelect_RetDone) {
    return Invalid(ModelFormat::kIges, name,
                   "the IGES reader rejected it (syntax or structure errors)");
  }
  RETURN_IF_ERROR(Checked(options));
  Handle(StopIndicator) progress = new StopIndicator(options.check);
  reader.TransferRoots(progress->Start());
  RETURN_IF_ERROR(progress->status());
  RETURN_IF_ERROR(CheckTransfer(reader, census, ModelFormat::kIges, name));
  return reader.OneShape();
}

absl::StatusOr<TopoDS_Shape> ReadNurbs(absl::string_view bytes, absl::string_view name) {
  ASSIGN_OR_RETURN(NurbsPatch patch, ParseNurbsPatch(bytes, name));
  TColgp_Array2OfPnt poles(1, patch.count_u, 1, patch.count_v);
  TColStd_Array2OfReal weights(1, patch.count_u, 1, patch.count_v);
  for (int i = 0; i < patch.count_u; ++i) {
    for (int j = 0; j < patch.count_v; ++j) {
      const NurbsPatch::Pole& p = patch.poles[static_cast<size_t>(i) * patch.count_v + j];
      poles.SetValue(i + 1, j + 1, gp_Pnt(p.x, p.y, p.z));
      weights.SetValue(i + 1, j + 1, p.w);
    }
  }
  // Full knot vectors -> distinct knots and multiplicities.
  auto split = [](const std::vector<double>& flat, std::vector<double>& knots,
                  std::vector<int>& mults) {
    for (double k : flat) {
      if (!knots.empty() && knots.back() == k) {
        ++mults.back();
      } else {
        knots.push_back(k);
        mults.push_back(1);
      }
    }
  };
  std::vector<double> ku, kv;
  std::vector<int> mu, mv;
  split(patch.knots_u, ku, mu);
  split(patch.knots_v, kv, mv);
  auto real_array = [](const std::vector<double>& x) {
    TColStd_Array1OfReal a(1, static_cast<int>(x.size()));
    for (size_t i = 0; i < x.size(); ++i) a.SetValue(static_cast<int>(i) + 1, x[i]);
    return a;
  };
  auto int_array = [](const std::vector<int>& x) {
    TColStd_Array1OfInteger a(1, static_cast<int>(x.size()));
    for (size_t i = 0; i < x.size(); ++i) a.SetValue(static_cast<int>(i) + 1, x[i]);
    return a;
  };
  Handle(Geom_BSplineSurface) surface =
      new Geom_BSplineSurface(poles, weights, real_array(ku), real_array(kv), int_array(mu),
                              int_array(mv), patch.degree_u, patch.degree_v);
  BRepBuilderAPI_MakeFace make(surface, Precision::Confusion());
  if (!make.IsDone())
    return Invalid(ModelFormat::kNurbs, name, "the kernel could not make a face of the patch");
  return TopoDS_Shape(make.Face());
}

FaceType TypeOf(GeomAbs_SurfaceType type) {
  switch (type) {
    case GeomAbs_Plane:
      return FaceType::kPlane;
    case GeomAbs_Cylinder:
      return FaceType::kCylinder;
    case GeomAbs_Cone:
      return FaceType::kCone;
    case GeomAbs_Sphere:
      return FaceType::kSphere;
    case GeomAbs_Torus:
      return FaceType::kTorus;
    case GeomAbs_BezierSurface:
      return FaceType::kBezier;
    case GeomAbs_BSplineSurface:
      return FaceType::kBSpline;
    case GeomAbs_SurfaceOfRevolution:
      return FaceType::kRevolution;
    case GeomAbs_SurfaceOfExtrusion:
      return FaceType::kExtrusion;
    case GeomAbs_OffsetSurface:
      return FaceType::kOffset;
    default:
      return FaceType::kOther;
  }
}

// The edges of a planar face often carry no p-curve; the kernel then projects
// the edge's 3D curve onto the plane on every question it is asked about the
// face (BRep_Tool::CurveOnPlane), which made the trim classifier's answers
// near the boundary ~20 us each. Storing that same projection on the edge
// once (BRepLib::BuildPCurveForEdgeOnPlane) leaves every answer as it was. An
// edge the kernel will not update keeps computing it.
void StorePlanePcurves(const TopoDS_Face& face) {
  if (BRepAdaptor_Surface(face, false).GetType() != GeomAbs_Plane) return;
  for (TopExp_Explorer it(face, TopAbs_EDGE); it.More(); it.Next()) {
    try {
      OCC_CATCH_SIGNALS
      BRepLib::BuildPCurveForEdgeOnPlane(TopoDS::Edge(it.Current()), face);
    } catch (const Standard_Failure&) {
    }
  }
}

absl::StatusOr<Face> MakeFace(const TopoDS_Face& face, int index, ModelFormat format,
                              absl::string_view name, const LoadOptions& options) {
  auto bad = [&](absl::string_view what) {
    return Invalid(format, name, absl::StrCat("face ", index, " ", what));
  };
  StorePlanePcurves(face);
  ParameterBox box;
  BRepTools::UVBounds(face, box.u0, box.u1, box.v0, box.v1);
  for (double x : {box.u0, box.u1, box.v0, box.v1}) {
    if (!std::isfinite(x) || Precision::IsInfinite(x))
      return bad("is unbounded (an infinite surface without trim)");
  }
  if (!(box.u1 > box.u0) || !(box.v1 > box.v0)) return bad("has an empty parameter box");
  const bool reversed = face.Orientation() == TopAbs_REVERSED;
  const UnitSquareMap map{box, reversed};
  GProp_GProps props;
  BRepGProp::SurfaceProperties(face, props);
  double area = std::abs(props.Mass());
  const gp_Pnt c = props.CentreOfMass();
  Vec3 centroid{c.X(), c.Y(), c.Z()};
  if (!std::isfinite(area) || !IsFinite(centroid))
    return bad("has a non-finite area (NaN or infinite geometry)");
  const BRepAdaptor_Surface adaptor(face, true);
  auto surface = std::make_shared<FaceSurface>(
      face, map, options.closed_forms ? ClosedForm::Extract(adaptor) : std::nullopt);
  for (double s : {0.0, 0.5, 1.0}) {
    for (double t : {0.0, 0.5, 1.0}) {
      if (!IsFinite(surface->Point(s, t)))
        return bad("has non-finite points (NaN or infinite coordinates)");
    }
  }
  // A face thinner on average than the kernel's own tolerance has no area:
  // its integral is rounding noise (a loop of collinear points gives ~1e-16)
  // and its trim cannot be classified, so it takes no samples (Face::area()
  // 0) and its noisy centre of mass is not used (the bounding box's centre).
  Bnd_Box bounds;
  BRepBndLib::Add(face, bounds, /*useTriangulation=*/Standard_False);
  const double diagonal = bounds.IsVoid() ? 0 : std::sqrt(bounds.SquareExtent());
  if (!(area > Precision::Confusion() * diagonal)) {
    area = 0;
    if (!bounds.IsVoid()) {
      double x0, y0, z0, x1, y1, z1;
      bounds.Get(x0, y0, z0, x1, y1, z1);
      centroid = {0.5 * (x0 + x1), 0.5 * (y0 + y1), 0.5 * (z0 + z1)};
    }
    if (!IsFinite(centroid)) centroid = surface->Point(0.5, 0.5);
  }
  auto trim = std::make_shared<FaceTrim>(face, map, options.trim_tolerance);
  const bool trimmed = trim->trimmed();  // before `trim` is moved from
  return Face(index, TypeOf(adaptor.GetType()), area, box, reversed, centroid, trimmed,
              std::move(surface), std::move(trim));
}

// The file read into one shape by the kernel's reader, with every check of
// the read. REQUIRES: g_reader_mutex held; for IGES, `iges_path` holds the
// bytes.
absl::StatusOr<TopoDS_Shape> ReadShape(ModelFormat format, absl::string_view bytes,
                                       const ModelCensus& census, const std::string& iges_path,
                                       absl::string_view name, const LoadOptions& options) {
  switch (format) {
    case ModelFormat::kStep:
      return ReadStep(bytes, census, name, options);
    case ModelFormat::kIges:
      return ReadIges(iges_path, census, name, options);
    case ModelFormat::kNurbs:
      return ReadNurbs(bytes, name);
    case ModelFormat::kObj:
    case ModelFormat::kPly:
      break;  // refused by Prepare
  }
  return absl::InternalError("not a CAD format");
}

// The model of a shape's faces, in the order TopExp::MapShapes finds them.
absl::StatusOr<std::shared_ptr<const Model>> ModelFromShape(const TopoDS_Shape& shape,
                                                            ModelFormat format,
                                                            absl::string_view name,
                                                            const LoadOptions& options) {
  TopTools_IndexedMapOfShape map;
  if (!shape.IsNull()) TopExp::MapShapes(shape, TopAbs_FACE, map);
  if (map.Extent() == 0) return Invalid(format, name, "empty model: it has no faces");
  std::vector<Face> faces;
  faces.reserve(map.Extent());
  bool any_area = false;
  for (int i = 1; i <= map.Extent(); ++i) {
    RETURN_IF_ERROR(Checked(options));
    ASSIGN_OR_RETURN(Face face, MakeFace(TopoDS::Face(map(i)), i - 1, format, name, options));
    any_area = any_area || face.area() > 0;
    faces.push_back(std::move(face));
  }
  if (!any_area) {
    constexpr size_t kNamed = 8;
    std::string named;
    for (size_t i = 0; i < std::min(faces.size(), kNamed); ++i)
      absl::StrAppend(&named, i ? ", " : "", i);
    if (faces.size() > kNamed) absl::StrAppend(&named, ", ...");
    return Invalid(
        format, name,
        absl::StrCat("has no face with area: its ", faces.size(), " faces (", named,
                     ") are thinner than the kernel's tolerance (", Precision::Confusion(),
                     " model units); a degenerate or collapsed model? fix or re-export it"));
  }
  return std::make_shared<const Model>(std::string(name), std::move(faces));
}

// `work()` (kernel work returning a StatusOr) with the kernel's exceptions,
// and the faults it turns into exceptions (cad/internal/kernel_setup.h), as
// statuses. A fault abandons the frames below without their destructors: it
// leaks the kernel's objects of this work, nothing else (no lock or file of
// ours lives below here).
template <typename Work>
auto Guarded(ModelFormat format, absl::string_view name, const Work& work) -> decltype(work()) {
  try {
    OCC_CATCH_SIGNALS
    return work();
  } catch (const Standard_Failure& e) {
    return Invalid(format, name,
                   absl::StrCat("the kernel failed on it: ", Echo(e.GetMessageString()), " (",
                                Echo(e.DynamicType()->Name()), ")"));
  } catch (const std::bad_alloc&) {
    return absl::ResourceExhaustedError(
        absl::StrCat(FormatName(format), " file ", name, ": out of memory while reading it"));
  } catch (const std::exception& e) {
    return absl::InternalError(
        absl::StrCat(FormatName(format), " file ", name, ": ", Echo(e.what())));
  }
}

// What Load and ReadToBrep check before the kernel sees the bytes: the size,
// the framing and the preflight; for IGES, the private file the reader reads.
struct Prepared {
  ModelCensus census;
  TempFile file;
};
absl::Status Prepare(ModelFormat format, absl::string_view bytes, absl::string_view name,
                     const LoadOptions& options, Prepared* prepared) {
  if (!IsCadFormat(format)) {
    return absl::InvalidArgumentError(
        absl::StrCat(FormatName(format), " is a mesh format, not a CAD one"));
  }
  if (bytes.size() > options.max_bytes) {
    return absl::ResourceExhaustedError(
        absl::StrCat(absl::AsciiStrToUpper(FormatName(format)), " file ", name, " has ",
                     bytes.size(), " bytes, above the limit of ", options.max_bytes, " bytes"));
  }
  if (format == ModelFormat::kStep) {
    RETURN_IF_ERROR(CheckStepFraming(bytes, name));
    auto step = PreflightStep(bytes, options.preflight);
    if (!step.ok()) return Invalid(format, name, step.status().message());
    prepared->census = *std::move(step);
  }
  if (format == ModelFormat::kIges) {
    RETURN_IF_ERROR(CheckIgesFraming(bytes, name));
    auto iges = PreflightIges(bytes, options.preflight);
    if (!iges.ok()) return Invalid(format, name, iges.status().message());
    prepared->census = *std::move(iges);
    RETURN_IF_ERROR(prepared->file.Write(bytes));  // IGESControl_Reader reads only files
  }
  SilenceKernelMessages();
  ConvertKernelSignals();
  return absl::OkStatus();
}

}  // namespace

bool IsCadFormat(ModelFormat format) {
  return format == ModelFormat::kStep || format == ModelFormat::kIges ||
         format == ModelFormat::kNurbs;
}

absl::StatusOr<ModelFormat> ParseModelFormat(absl::string_view text) {
  const std::string lower = absl::AsciiStrToLower(text);
  std::optional<ModelFormat> format = ModelFormatFromName(lower);
  for (const ModelExtension& e : ModelExtensions()) {
    if (!format && e.extension.substr(1) == lower) format = e.format;
  }
  if (format && IsCadFormat(*format)) return *format;
  return absl::InvalidArgumentError(
      absl::StrCat("unknown model format '", text, "'; expected step, iges or nurbs"));
}

namespace {

// Reads `bytes` into a shape with every check, then returns `then(shape)`.
// Our own resources (the temporary file, the lock) are taken outside
// Guarded, whose signal guard skips destructors of the frames between the
// fault and itself.
template <typename Then>
auto ReadThen(ModelFormat format, absl::string_view bytes, absl::string_view untrusted_name,
              const LoadOptions& options, const Then& then)
    -> decltype(then(TopoDS_Shape(), std::string())) {
  const std::string name = Echo(untrusted_name, kMaxNameEcho);
  Prepared prepared;
  RETURN_IF_ERROR(Prepare(format, bytes, name, options, &prepared));
  absl::MutexLock lock(&g_reader_mutex);
  return Guarded(format, name, [&]() -> decltype(then(TopoDS_Shape(), std::string())) {
    ASSIGN_OR_RETURN(TopoDS_Shape shape, ReadShape(format, bytes, prepared.census,
                                                   prepared.file.path(), name, options));
    return then(shape, name);
  });
}

}  // namespace

absl::StatusOr<std::shared_ptr<const Model>> Load(ModelFormat format, absl::string_view bytes,
                                                  absl::string_view untrusted_name,
                                                  const LoadOptions& options) {
  return ReadThen(format, bytes, untrusted_name, options,
                  [&](const TopoDS_Shape& shape, const std::string& name) {
                    return ModelFromShape(shape, format, name, options);
                  });
}

absl::StatusOr<std::string> ReadToBrep(ModelFormat format, absl::string_view bytes,
                                       absl::string_view untrusted_name,
                                       const LoadOptions& options) {
  return ReadThen(
      format, bytes, untrusted_name, options,
      [&](const TopoDS_Shape& shape, const std::string& name) -> absl::StatusOr<std::string> {
        // Every check Load makes of the faces, here, where a fault
        // costs this process.
        RETURN_IF_ERROR(ModelFromShape(shape, format, name, options).status());
        std::ostringstream out;
        BinTools::Write(shape, out, /*theWithTriangles=*/Standard_False,
                        /*theWithNormals=*/Standard_False, BinTools_FormatVersion_CURRENT);
        return out.str();
      });
}

absl::StatusOr<std::shared_ptr<const Model>> LoadBrep(absl::string_view brep, ModelFormat format,
                                                      absl::string_view untrusted_name,
                                                      const LoadOptions& options) {
  const std::string name = Echo(untrusted_name, kMaxNameEcho);
  SilenceKernelMessages();
  ConvertKernelSignals();
  return Guarded(format, name, [&]() -> absl::StatusOr<std::shared_ptr<const Model>> {
    std::istringstream in{std::string(brep)};
    TopoDS_Shape shape;
    BinTools::Read(shape, in);
    if (shape.IsNull())
      return absl::InternalError(
          absl::StrCat("the model check's shape of ", name, " could not be read back"));
    return ModelFromShape(shape, format, name, options);
  });
}

}  // namespace sfc::cad
