#include "cad/model.h"

#include <utility>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "cad/face_order.h"
#include "cad/internal/occ_face.h"

namespace sfc::cad {

absl::string_view FaceTypeName(FaceType type) {
  switch (type) {
    case FaceType::kPlane:
      return "plane";
    case FaceType::kCylinder:
      return "cylinder";
    case FaceType::kCone:
      return "cone";
    case FaceType::kSphere:
      return "sphere";
    case FaceType::kTorus:
      return "torus";
    case FaceType::kBSpline:
      return "bspline";
    case FaceType::kBezier:
      return "bezier";
    case FaceType::kRevolution:
      return "revolution";
    case FaceType::kExtrusion:
      return "extrusion";
    case FaceType::kOffset:
      return "offset";
    case FaceType::kOther:
      return "other";
  }
  return "other";
}

Face::Face(int index, FaceType type, double area, ParameterBox box, bool reversed, Vec3 centroid,
           bool trimmed, std::shared_ptr<const Surface> surface,
           std::shared_ptr<const FaceTrim> trim)
    : index_(index),
      type_(type),
      area_(area),
      box_(box),
      reversed_(reversed),
      centroid_(centroid),
      trimmed_(trimmed),
      surface_(std::move(surface)),
      trim_(std::move(trim)) {}

bool Face::Contains(double s, double t) const { return trim_->Contains(s, t); }
bool Face::KeepsWhole(double s0, double s1, double t0, double t1) const {
  return trim_->KeepsWhole(s0, s1, t0, t1);
}
void Face::ContainsMany(const double* s, const double* t, size_t n, uint8_t* inside) const {
  trim_->ContainsMany(s, t, n, inside);
}
double Face::TrimGridCell() { return 1.0 / FaceTrim::kGridSide; }

double Face::Clearance(double s, double t) const { return trim_->Clearance(s, t); }

bool Face::closed_form() const {
  const auto* face = dynamic_cast<const FaceSurface*>(surface_.get());
  return face && face->closed_form();
}

CellState Face::Classify(double s0, double s1, double t0, double t1) const {
  return trim_->Classify(s0, s1, t0, t1);
}

Model::Model(std::string name, std::vector<Face> faces)
    : name_(std::move(name)), faces_(std::move(faces)) {
  // Faces with area in the Hilbert order of their centroids; faces without
  // (no samples) after them in file order, so they move no other face.
  std::vector<Vec3> centroids;
  std::vector<int> with_area, without;
  for (const Face& face : faces_) {
    total_area_ += face.area();
    if (face.area() > 0) {
      with_area.push_back(face.index());
      centroids.push_back(face.centroid());
    } else {
      without.push_back(face.index());
    }
  }
  for (int i : HilbertOrder(centroids)) curve_order_.push_back(with_area[i]);
  curve_order_.insert(curve_order_.end(), without.begin(), without.end());
}

std::string DescribeModel(const Model& model) {
  std::string out = absl::StrFormat("model %s: %d faces, total area %.10g\n", model.name(),
                                    model.faces().size(), model.total_area());
  absl::StrAppendFormat(&out, "%5s  %-10s  %16s  %-51s  %-8s  %s\n", "face", "type", "area",
                        "parameter box [u0, u1] x [v0, v1]", "reversed", "trimmed");
  for (const Face& face : model.faces()) {
    const ParameterBox& b = face.parameter_box();
    absl::StrAppendFormat(&out,
                          "%5d  %-10s  %16.10g  [%11.6g, %11.6g] x [%11.6g, %11.6g]  %-8s  %s\n",
                          face.index(), FaceTypeName(face.type()), face.area(), b.u0, b.u1, b.v0,
                          b.v1, face.reversed() ? "yes" : "no", face.trimmed() ? "yes" : "no");
  }
  const auto without_area = std::count_if(model.faces().begin(), model.faces().end(),
                                          [](const Face& face) { return !(face.area() > 0); });
  if (without_area > 0) {
    absl::StrAppendFormat(&out,
                          "%d faces have no area (area 0: thinner than the kernel's tolerance) "
                          "and take no samples\n",
                          without_area);
  }
  absl::StrAppend(&out, "curve order: ", absl::StrJoin(model.curve_order(), " "), "\n");
  return out;
}

}  // namespace sfc::cad
