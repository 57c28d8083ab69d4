// Tests of cad/: models the project writes itself with OpenCASCADE
// (cad/fixtures.h), loaded back from bytes, checked against exact formulas.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <numeric>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "absl/strings/str_replace.h"
#include "cad/face_order.h"
#include "cad/fixtures.h"
#include "cad/load.h"
#include "cad/model.h"
#include "cad/nurbs_patch.h"
#include "gtest/gtest.h"
#include "tests/cad_test_util.h"

namespace sfc::cad {
namespace {

using fixtures::Solid;
constexpr double kPi = 3.14159265358979323846;

using testing::Bytes;

std::shared_ptr<const Model> LoadOk(Solid solid, ModelFormat format) {
  auto model = Load(format, Bytes(solid, format), fixtures::SolidName(solid));
  EXPECT_TRUE(model.ok()) << model.status();
  return model.ok() ? *model : nullptr;
}

void ExpectNear(const Vec3& a, const Vec3& b, double tol, const std::string& what) {
  EXPECT_NEAR(a.x, b.x, tol) << what;
  EXPECT_NEAR(a.y, b.y, tol) << what;
  EXPECT_NEAR(a.z, b.z, tol) << what;
}

// Jet against central differences of Point (first derivatives) and of the
// first derivatives (second ones), at interior points.
void ExpectJetMatchesDifferences(const Surface& surface, double scale, const std::string& what) {
  const double h = 1e-5;
  for (double s : {0.13, 0.5, 0.77}) {
    for (double t : {0.21, 0.5, 0.64}) {
      const SurfaceJet jet = surface.Jet(s, t, 2);
      const std::string at = what + " at (" + std::to_string(s) + ", " + std::to_string(t) + ")";
      ExpectNear(jet.p, surface.Point(s, t), 1e-12 * scale, at + " p");
      ExpectNear(jet.fu, (surface.Point(s + h, t) - surface.Point(s - h, t)) * (0.5 / h),
                 1e-6 * scale, at + " fu");
      ExpectNear(jet.fv, (surface.Point(s, t + h) - surface.Point(s, t - h)) * (0.5 / h),
                 1e-6 * scale, at + " fv");
      const SurfaceJet su = surface.Jet(s + h, t, 1), sd = surface.Jet(s - h, t, 1);
      const SurfaceJet tu = surface.Jet(s, t + h, 1), td = surface.Jet(s, t - h, 1);
      ExpectNear(jet.fuu, (su.fu - sd.fu) * (0.5 / h), 1e-5 * scale, at + " fuu");
      ExpectNear(jet.fuv, (tu.fu - td.fu) * (0.5 / h), 1e-5 * scale, at + " fuv");
      ExpectNear(jet.fvv, (tu.fv - td.fv) * (0.5 / h), 1e-5 * scale, at + " fvv");
    }
  }
}

// Integral of the area element over the points of an n x n midpoint grid
// that the face contains: the trimmed area, through the classifier.
double ClassifiedArea(const Face& face, int n) {
  double sum = 0;
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      const double s = (i + 0.5) / n, t = (j + 0.5) / n;
      if (!face.Contains(s, t)) continue;
      const SurfaceJet jet = face.surface().Jet(s, t, 1);
      sum += Norm(Cross(jet.fu, jet.fv));
    }
  }
  return sum / (double(n) * n);
}

TEST(FaceOrder, HilbertOrderIsAShortPermutation) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> uniform(-3, 5);
  std::vector<Vec3> points(2000);
  for (Vec3& p : points) p = {uniform(rng), uniform(rng), 0.25 * uniform(rng)};
  const std::vector<int> order = HilbertOrder(points);
  std::vector<int> sorted = order;
  std::sort(sorted.begin(), sorted.end());
  std::vector<int> identity(points.size());
  std::iota(identity.begin(), identity.end(), 0);
  ASSERT_EQ(sorted, identity);
  auto length = [&](const std::vector<int>& o) {
    double sum = 0;
    for (size_t i = 1; i < o.size(); ++i) sum += Norm(points[o[i]] - points[o[i - 1]]);
    return sum;
  };
  // Random order: ~ n x mean distance (~4); a space-filling order is far shorter.
  EXPECT_LT(length(order), 0.15 * length(identity));
}

TEST(CadSphere, AreaDerivativesAndOutwardNormal) {
  auto model = LoadOk(Solid::kSphere, ModelFormat::kStep);
  ASSERT_NE(model, nullptr);
  ASSERT_EQ(model->faces().size(), 1u);
  const Face& face = model->faces()[0];
  const double r = fixtures::kSphereRadius;
  EXPECT_EQ(face.type(), FaceType::kSphere);
  EXPECT_NEAR(face.area(), 4 * kPi * r * r, 1e-6 * r * r);
  EXPECT_FALSE(face.trimmed());
  ExpectJetMatchesDifferences(face.surface(), r, "sphere");
  // Closed form: OCCT's sphere is r (cos v cos u, cos v sin u, sin v).
  const ParameterBox& b = face.parameter_box();
  EXPECT_NEAR(b.u1 - b.u0, 2 * kPi, 1e-9);
  EXPECT_NEAR(b.v1 - b.v0, kPi, 1e-9);
  for (double s : {0.1, 0.4, 0.9}) {
    for (double t : {0.2, 0.5, 0.8}) {
      const double du = face.reversed() ? -(b.u1 - b.u0) : b.u1 - b.u0, dv = b.v1 - b.v0;
      const double u = face.reversed() ? b.u1 - s * (b.u1 - b.u0) : b.u0 + s * (b.u1 - b.u0);
      const double v = b.v0 + t * dv;
      const SurfaceJet jet = face.surface().Jet(s, t, 2);
      const std::string at =
          "sphere closed form at s=" + std::to_string(s) + " t=" + std::to_string(t);
      ExpectNear(
          jet.p,
          Vec3{r * std::cos(v) * std::cos(u), r * std::cos(v) * std::sin(u), r * std::sin(v)}, 1e-9,
          at);
      ExpectNear(jet.fu,
                 Vec3{-r * std::cos(v) * std::sin(u), r * std::cos(v) * std::cos(u), 0} * du, 1e-9,
                 at);
      ExpectNear(
          jet.fv,
          Vec3{-r * std::sin(v) * std::cos(u), -r * std::sin(v) * std::sin(u), r * std::cos(v)} *
              dv,
          1e-9, at);
      ExpectNear(
          jet.fuu,
          Vec3{-r * std::cos(v) * std::cos(u), -r * std::cos(v) * std::sin(u), 0} * (du * du), 1e-8,
          at);
      ExpectNear(jet.fuv,
                 Vec3{r * std::sin(v) * std::sin(u), -r * std::sin(v) * std::cos(u), 0} * (du * dv),
                 1e-8, at);
      ExpectNear(jet.fvv, jet.p * -(dv * dv), 1e-8, at);
      EXPECT_GT(Dot(Cross(jet.fu, jet.fv), jet.p), 0) << at << ": the normal points inward";
    }
  }
}

TEST(CadCylinder, FacesAreasClosedFormAndOutwardNormals) {
  auto model = LoadOk(Solid::kCylinder, ModelFormat::kStep);
  ASSERT_NE(model, nullptr);
  const double r = fixtures::kCylinderRadius, h = fixtures::kCylinderHeight;
  ASSERT_EQ(model->faces().size(), 3u);
  int lateral = 0, caps = 0;
  for (const Face& face : model->faces()) {
    const std::string what = "face " + std::to_string(face.index());
    if (face.type() == FaceType::kCylinder) {
      ++lateral;
      EXPECT_NEAR(face.area(), 2 * kPi * r * h, 1e-6 * r * h);
      const ParameterBox& b = face.parameter_box();
      const double du = face.reversed() ? -(b.u1 - b.u0) : b.u1 - b.u0;
      for (double s : {0.1, 0.6}) {
        for (double t : {0.3, 0.7}) {
          const double u = face.reversed() ? b.u1 - s * (b.u1 - b.u0) : b.u0 + s * (b.u1 - b.u0);
          const SurfaceJet jet = face.surface().Jet(s, t, 2);
          ExpectNear(jet.p, Vec3{r * std::cos(u), r * std::sin(u), b.v0 + t * (b.v1 - b.v0)}, 1e-9,
                     what);
          ExpectNear(jet.fu, Vec3{-r * std::sin(u), r * std::cos(u), 0} * du, 1e-9, what);
          ExpectNear(jet.fv, Vec3{0, 0, b.v1 - b.v0}, 1e-9, what);
          ExpectNear(jet.fuu, Vec3{-r * std::cos(u), -r * std::sin(u), 0} * (du * du), 1e-8, what);
        }
      }
    } else {
      ++caps;
      EXPECT_EQ(face.type(), FaceType::kPlane) << what;
      EXPECT_NEAR(face.area(), kPi * r * r, 1e-6 * r * r) << what;
      EXPECT_TRUE(face.trimmed()) << what << ": a disc in its square";
      EXPECT_NEAR(ClassifiedArea(face, 300), face.area(), 0.01 * face.area()) << what;
    }
    ExpectJetMatchesDifferences(face.surface(), r + h, what);
    // Convex solid: outward normals point away from the centroid.
    const Vec3 centre{0, 0, h / 2};
    for (double s : {0.3, 0.5, 0.7}) {
      for (double t : {0.3, 0.5, 0.7}) {
        if (!face.Contains(s, t)) continue;
        const SurfaceJet jet = face.surface().Jet(s, t, 1);
        EXPECT_GT(Dot(Cross(jet.fu, jet.fv), jet.p - centre), 0)
            << what << ": the normal points inward";
      }
    }
  }
  EXPECT_EQ(lateral, 1);
  EXPECT_EQ(caps, 2);
}

std::vector<double> ExpectedBoxAreas() {
  using namespace fixtures;
  const double f = kFilletRadius, r = kHoleRadius;
  const double cap = kBoxX * kBoxY - f * f * (1 - kPi / 4) - kPi * r * r;
  std::vector<double> areas = {cap,
                               cap,
                               kBoxX * kBoxZ,
                               kBoxY * kBoxZ,
                               (kBoxX - f) * kBoxZ,
                               (kBoxY - f) * kBoxZ,
                               kPi / 2 * f * kBoxZ,
                               2 * kPi * r * kBoxZ};
  std::sort(areas.begin(), areas.end());
  return areas;
}

void ExpectBoxAreas(const Model& model) {
  std::vector<double> areas;
  for (const Face& face : model.faces()) areas.push_back(face.area());
  std::sort(areas.begin(), areas.end());
  const std::vector<double> expected = ExpectedBoxAreas();
  ASSERT_EQ(areas.size(), expected.size()) << DescribeModel(model);
  for (size_t i = 0; i < areas.size(); ++i)
    EXPECT_NEAR(areas[i], expected[i], 1e-6 * expected[i]) << i;
  EXPECT_NEAR(model.total_area(), std::accumulate(expected.begin(), expected.end(), 0.0), 1e-5);
}

TEST(CadBoxWithHole, FaceAreasAreExact) {
  for (ModelFormat format : {ModelFormat::kStep, ModelFormat::kIges}) {
    SCOPED_TRACE(std::string(ModelFormatName(format)));
    auto model = LoadOk(Solid::kBoxWithHole, format);
    ASSERT_NE(model, nullptr);
    ExpectBoxAreas(*model);
  }
}

TEST(CadBoxWithHole, DerivativesMatchDifferencesAndHoleNormalPointsIntoHole) {
  auto model = LoadOk(Solid::kBoxWithHole, ModelFormat::kStep);
  ASSERT_NE(model, nullptr);
  for (const Face& face : model->faces()) {
    ExpectJetMatchesDifferences(face.surface(), 100, "face " + std::to_string(face.index()));
    if (face.type() != FaceType::kCylinder || std::abs(face.area() - 2 * kPi * 5 * 20) > 1e-3)
      continue;
    const SurfaceJet jet = face.surface().Jet(0.3, 0.5, 1);
    const Vec3 axis{fixtures::kBoxX / 2, fixtures::kBoxY / 2, jet.p.z};
    EXPECT_GT(Dot(Cross(jet.fu, jet.fv), axis - jet.p), 0)
        << "the hole's normal leaves the solid into the hole";
  }
}

// Cells the classifier calls inside (outside) hold only points the kernel
// puts in (out of) the face; the classified area matches the trimmed area.
TEST(CadBoxWithHole, ClassifierAgreesWithPointsAndAreas) {
  auto model = LoadOk(Solid::kBoxWithHole, ModelFormat::kStep);
  ASSERT_NE(model, nullptr);
  int trimmed_faces = 0;
  for (const Face& face : model->faces()) {
    const std::string what = "face " + std::to_string(face.index());
    const int cells = 40, probes = 3;
    int straddling = 0;
    for (int i = 0; i < cells; ++i) {
      for (int j = 0; j < cells; ++j) {
        const double s0 = double(i) / cells, s1 = double(i + 1) / cells;
        const double t0 = double(j) / cells, t1 = double(j + 1) / cells;
        const CellState state = face.Classify(s0, s1, t0, t1);
        if (state == CellState::kStraddles) {
          ++straddling;
          continue;
        }
        for (int a = 0; a <= probes; ++a) {
          for (int b = 0; b <= probes; ++b) {
            const double s = s0 + (s1 - s0) * a / probes, t = t0 + (t1 - t0) * b / probes;
            EXPECT_EQ(face.Contains(s, t), state == CellState::kInside)
                << what << " cell (" << i << ", " << j << ") at (" << s << ", " << t << ")";
          }
        }
      }
    }
    if (face.trimmed()) {
      ++trimmed_faces;
      EXPECT_GT(straddling, 0) << what << " is trimmed, yet no cell straddles its trim";
      EXPECT_LT(straddling, cells * cells / 2) << what;
    } else {
      EXPECT_EQ(straddling, 0) << what;
    }
    EXPECT_NEAR(ClassifiedArea(face, 300), face.area(), 0.01 * face.area()) << what;
  }
  EXPECT_GE(trimmed_faces, 2) << "the top and bottom faces have a hole";
}

// Random cells of every size, many near the trim: a cell called inside
// (outside) holds no point the kernel puts out of (in) the face.
TEST(CadBoxWithHole, RandomCellsOfAllSizesAreClassifiedSafely) {
  auto model = LoadOk(Solid::kBoxWithHole, ModelFormat::kStep);
  ASSERT_NE(model, nullptr);
  std::mt19937_64 rng(11);
  int decided = 0;
  for (const Face& face : model->faces()) {
    if (!face.trimmed()) continue;
    for (int k = 0; k < 1500; ++k) {
      const int depth = 2 + static_cast<int>(rng() % 11);
      const int cells = 1 << depth;
      double s0 = double(rng() % cells) / cells, t0 = double(rng() % cells) / cells;
      if (k % 2 == 1) {
        // A cell within a few cell widths of the hole, whose circle is
        // centred in the face's square (the box's parameters start at a corner).
        const double angle = 2 * kPi * double(rng() % 100000) / 100000;
        const double offset = (double(rng() % 1000) / 1000 - 0.5) * 6.0 / cells;
        const double s = 0.5 + (fixtures::kHoleRadius / fixtures::kBoxX + offset) * std::cos(angle);
        const double t = 0.5 + (fixtures::kHoleRadius / fixtures::kBoxY + offset) * std::sin(angle);
        s0 = std::clamp(std::floor(s * cells), 0.0, cells - 1.0) / cells;
        t0 = std::clamp(std::floor(t * cells), 0.0, cells - 1.0) / cells;
      }
      const double s1 = s0 + 1.0 / cells, t1 = t0 + 1.0 / cells;
      const CellState state = face.Classify(s0, s1, t0, t1);
      if (state == CellState::kStraddles) continue;
      ++decided;
      for (int a = 0; a <= 2; ++a) {
        for (int b = 0; b <= 2; ++b) {
          const double s = s0 + (s1 - s0) * a / 2, t = t0 + (t1 - t0) * b / 2;
          ASSERT_EQ(face.Contains(s, t), state == CellState::kInside)
              << "face " << face.index() << " cell [" << s0 << ", " << s1 << "] x [" << t0 << ", "
              << t1 << "] at (" << s << ", " << t << ")";
        }
      }
    }
  }
  EXPECT_GT(decided, 2000);
}

// The holed faces (top and bottom) of the box, with the plane's affine map:
// the unit square's point (s, t) is p0 + s fu + t fv (fu, fv orthogonal), so
// the hole is an exact ellipse in (s, t), a reference the kernel has no part in.
struct HoledFace {
  const Face* face;
  Vec3 p0, fu, fv;
  // Signed distance in space from the hole's circle, > 0 inside the face.
  double Beyond(double s, double t) const {
    const Vec3 p = p0 + fu * s + fv * t;
    return std::hypot(p.x - fixtures::kBoxX / 2, p.y - fixtures::kBoxY / 2) -
           fixtures::kHoleRadius;
  }
  // The unit-square point `off` mm beyond the hole's circle (inside the
  // face for off > 0) at `angle` about its centre.
  std::pair<double, double> AtOffset(double off, double angle) const {
    const Vec3 centre = Vec3{fixtures::kBoxX / 2, fixtures::kBoxY / 2, p0.z} - p0;
    const double r = fixtures::kHoleRadius + off;
    return {Dot(centre, fu) / Dot(fu, fu) + r * std::cos(angle) / Norm(fu),
            Dot(centre, fv) / Dot(fv, fv) + r * std::sin(angle) / Norm(fv)};
  }
};

std::vector<HoledFace> HoledFaces(const Model& model) {
  std::vector<HoledFace> out;
  for (const Face& face : model.faces()) {
    if (face.type() != FaceType::kPlane || !face.trimmed()) continue;
    const SurfaceJet jet = face.surface().Jet(0, 0, 1);
    if (std::abs(jet.fu.z) > 1e-12 || std::abs(jet.fv.z) > 1e-12) continue;  // not horizontal
    out.push_back({&face, jet.p, jet.fu, jet.fv});
  }
  return out;
}

// Points near the hole, from 1e-6 mm to 4 mm off its circle on either side:
// Contains matches the exact circle (the fine grid near the trim decides many
// of them without the kernel).
TEST(CadBoxWithHole, ContainsMatchesTheExactHoleNearItsEdge) {
  auto model = LoadOk(Solid::kBoxWithHole, ModelFormat::kStep);
  ASSERT_NE(model, nullptr);
  const auto faces = HoledFaces(*model);
  ASSERT_EQ(faces.size(), 2u);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> unit(0, 1);
  for (const HoledFace& h : faces) {
    int inside = 0, outside = 0;
    for (int k = 0; k < 20000; ++k) {
      const double angle = 2 * kPi * unit(rng);
      const double off = (k % 2 ? 1 : -1) * std::pow(10.0, -6 + 6.6 * unit(rng));  // mm
      const auto [s, t] = h.AtOffset(off, angle);
      const double beyond = h.Beyond(s, t);
      if (std::abs(beyond) < 1e-7) continue;  // within the tolerance: either answer
      const bool in = h.face->Contains(s, t);
      ASSERT_EQ(in, beyond > 0) << "face " << h.face->index() << " at (" << s << ", " << t
                                << "), " << beyond << " mm from the hole";
      (in ? inside : outside)++;
    }
    EXPECT_GT(inside, 9000);
    EXPECT_GT(outside, 9000);
  }
}

// ContainsMany answers as Contains point by point: near the hole (where the
// sub-cells, the exact trim and the kernel answer), anywhere in the square,
// and on untrimmed faces (every point inside).
TEST(CadBoxWithHole, ContainsManyAnswersAsContains) {
  auto model = LoadOk(Solid::kBoxWithHole, ModelFormat::kStep);
  ASSERT_NE(model, nullptr);
  const auto holed = HoledFaces(*model);
  ASSERT_EQ(holed.size(), 2u);
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> unit(0, 1);
  for (const Face& face : model->faces()) {
    std::vector<double> s, t;
    for (int k = 0; k < 4000; ++k) s.push_back(unit(rng)), t.push_back(unit(rng));
    for (const HoledFace& h : holed) {
      if (h.face != &face) continue;
      for (int k = 0; k < 4000; ++k) {
        const double off = (k % 2 ? 1 : -1) * std::pow(10.0, -6 + 6.6 * unit(rng));  // mm
        const auto [a, b] = h.AtOffset(off, 2 * kPi * unit(rng));
        s.push_back(a), t.push_back(b);
      }
    }
    s.insert(s.end(), {0, 1, 0, 1}), t.insert(t.end(), {0, 0, 1, 1});
    std::vector<uint8_t> inside(s.size(), 7);
    face.ContainsMany(s.data(), t.data(), s.size(), inside.data());
    int out = 0;
    for (size_t i = 0; i < s.size(); ++i) {
      ASSERT_EQ(inside[i], face.Contains(s[i], t[i]) ? 1 : 0)
          << "face " << face.index() << " at (" << s[i] << ", " << t[i] << ")";
      out += inside[i] == 0;
    }
    if (face.trimmed()) EXPECT_GT(out, 100) << "face " << face.index();
    if (!face.trimmed()) EXPECT_EQ(out, 0) << "face " << face.index();
  }
}

// KeepsWhole (a trimmed face's density is uniform on the cell, so the tree
// skips its error test there on a plane): Contains is true at every point of
// the closed cell, its sides and corners included, for cells of the tree's
// sizes at its positions and anywhere; and it holds for most cells away from
// the hole.
TEST(CadBoxWithHole, KeepsWholeOnlyWhereEveryPointIsInside) {
  auto model = LoadOk(Solid::kBoxWithHole, ModelFormat::kStep);
  ASSERT_NE(model, nullptr);
  std::mt19937_64 rng(10);
  std::uniform_real_distribution<double> unit(0, 1);
  for (const HoledFace& h : HoledFaces(*model)) {
    const Face& face = *h.face;
    int whole = 0, cells = 0;
    for (int depth = 3; depth <= 9; ++depth) {
      const double side = std::ldexp(1.0, -depth);
      for (int k = 0; k < 300; ++k, ++cells) {
        // Half the cells on the tree's grid, half anywhere.
        const double s0 = k % 2 ? std::floor(unit(rng) / side) * side : unit(rng) * (1 - side);
        const double t0 = k % 2 ? std::floor(unit(rng) / side) * side : unit(rng) * (1 - side);
        if (!face.KeepsWhole(s0, s0 + side, t0, t0 + side)) continue;
        ++whole;
        for (int i = 0; i <= 16; ++i) {
          for (int j = 0; j <= 16; ++j) {
            const double s = i == 16 ? s0 + side : s0 + i * (side / 16);
            const double t = j == 16 ? t0 + side : t0 + j * (side / 16);
            ASSERT_TRUE(face.Contains(s, t))
                << "face " << face.index() << " cell (" << s0 << ", " << t0 << ") side " << side
                << " at (" << s << ", " << t << ")";
          }
        }
      }
    }
    EXPECT_GT(whole, cells / 3) << "face " << face.index();
    EXPECT_LT(whole, cells) << "face " << face.index();
  }
}

// Clearance: every point nearer than it keeps the answer (checked on circles
// against the exact hole), and it is not uselessly small: at least half the
// distance to the hole where that is 1e-4 of the square or more.
TEST(CadBoxWithHole, ClearanceBoundsTheDistanceToTheTrimFromBelow) {
  auto model = LoadOk(Solid::kBoxWithHole, ModelFormat::kStep);
  ASSERT_NE(model, nullptr);
  std::mt19937_64 rng(6);
  std::uniform_real_distribution<double> unit(0, 1);
  for (const HoledFace& h : HoledFaces(*model)) {
    const double stretch = std::max(Norm(h.fu), Norm(h.fv));  // mm per unit of the square, at most
    for (int k = 0; k < 400; ++k) {
      const double angle = 2 * kPi * unit(rng);
      const double off = (k % 2 ? 1 : -1) * std::pow(10.0, -5 + 5.5 * unit(rng));  // mm
      const auto [s, t] = h.AtOffset(off, angle);
      const double clear = h.face->Clearance(s, t);
      ASSERT_GE(clear, 0);
      const bool in = h.Beyond(s, t) > 0;
      for (int d = 0; d < 32; ++d) {
        const double qs = s + 0.999 * clear * std::cos(2 * kPi * d / 32);
        const double qt = t + 0.999 * clear * std::sin(2 * kPi * d / 32);
        ASSERT_EQ(h.Beyond(qs, qt) > 0, in) << "clearance " << clear << " at (" << s << ", " << t
                                            << ") reaches across the hole's edge";
        ASSERT_EQ(h.face->Contains(qs, qt), in);
      }
      const double distance = std::abs(h.Beyond(s, t)) / stretch;  // <= the distance in (s, t)
      if (distance >= 1e-4) EXPECT_GE(clear, 0.5 * distance) << "at (" << s << ", " << t << ")";
    }
  }
}

// A hole bounded by a B-spline: the kernel's classifier can err a little
// beyond the curve's boxes there (its polygon's error allowance is measured
// at chord midpoints), so no classified piece may spread one of its answers.
// Points at least 0.12 mm (0.003 of the square) from the curve are
// classified as the curve itself says (the winding of 4 000 of its points).
TEST(CadSplineHole, PointsAwayFromTheCurveAreClassifiedAsTheCurveSays) {
  const auto hole = fixtures::SplineHolePoints(4000);
  auto inside_hole = [&](double x, double y) {
    bool in = false;
    for (size_t i = 0, j = hole.size() - 1; i < hole.size(); j = i++) {
      const auto [xi, yi] = hole[i];
      const auto [xj, yj] = hole[j];
      if ((yi > y) != (yj > y) && x < (xj - xi) * (y - yi) / (yj - yi) + xi) in = !in;
    }
    return in;
  };
  auto distance = [&](double x, double y) {
    double best = 1e300;
    for (const auto& [px, py] : hole) best = std::min(best, std::hypot(px - x, py - y));
    return best;  // at most 0.01 mm above the distance to the curve (points 0.02 mm apart)
  };
  for (ModelFormat format : {ModelFormat::kStep, ModelFormat::kIges}) {
    auto model = LoadOk(Solid::kSplineHolePlate, format);
    ASSERT_NE(model, nullptr);
    ASSERT_EQ(model->faces().size(), 1u);
    const Face& face = model->faces()[0];
    ASSERT_TRUE(face.trimmed());
    std::mt19937_64 rng(12);
    std::uniform_real_distribution<double> unit(0, 1);
    int checked = 0;
    for (int k = 0; k < 8000; ++k) {
      // Half uniform, half within 0.4 mm of the curve.
      double s = unit(rng), t = unit(rng);
      if (k % 2) {
        const auto& [hx, hy] = hole[static_cast<size_t>(unit(rng) * hole.size())];
        const Vec3 c = face.surface().Point(0.5, 0.5);
        const Vec3 e = face.surface().Point(1, 1) - face.surface().Point(0, 0);
        const double ox = (unit(rng) - 0.5) * 0.8, oy = (unit(rng) - 0.5) * 0.8;
        s = std::clamp(0.5 + (hx + ox - c.x) / e.x, 0.0, 1.0);
        t = std::clamp(0.5 + (hy + oy - c.y) / e.y, 0.0, 1.0);
      }
      const Vec3 p = face.surface().Point(s, t);
      if (distance(p.x, p.y) < 0.12) continue;
      ++checked;
      ASSERT_EQ(face.Contains(s, t), !inside_hole(p.x, p.y))
          << ModelFormatName(format) << " at (" << s << ", " << t << ") = (" << p.x << ", " << p.y
          << "), " << distance(p.x, p.y) << " mm from the curve";
    }
    EXPECT_GT(checked, 4800);
  }
}

// Refining a straddling cell ends in cells the boundary boxes leave alone.
TEST(CadBoxWithHole, StraddlingCellsShrinkToTheBoundary) {
  auto model = LoadOk(Solid::kBoxWithHole, ModelFormat::kStep);
  ASSERT_NE(model, nullptr);
  for (const Face& face : model->faces()) {
    if (!face.trimmed()) continue;
    const int n = 256;  // cells of 1/256: a band of a few cells along the trim straddles
    int straddling = 0;
    for (int i = 0; i < n; ++i) {
      for (int j = 0; j < n; ++j) {
        straddling += face.Classify(double(i) / n, double(i + 1) / n, double(j) / n,
                                    double(j + 1) / n) == CellState::kStraddles;
      }
    }
    EXPECT_LT(straddling, 0.05 * n * n) << "face " << face.index();
  }
}

// A 6 x 6 biquadratic patch with four spans per direction: evaluation moves
// between spans all the time, so the kernel's B-spline span cache (mutable in
// GeomAdaptor_Surface) would be rebuilt under another thread's feet if
// adaptors were shared.
std::string MultiSpanPatch() {
  std::string text =
      "sfcsampler-nurbs 1\ndegree 2 2\ncount 6 6\n"
      "knots_u 0 0 0 0.25 0.5 0.75 1 1 1\nknots_v 0 0 0 0.2 0.5 0.7 1 1 1\n";
  for (int i = 0; i < 6; ++i) {
    for (int j = 0; j < 6; ++j) {
      text += "pole " + std::to_string(i) + " " + std::to_string(j) + " " +
              std::to_string((i * 7 + j * 3) % 5 * 0.3) + " " + std::to_string(1 + (i + j) % 3) +
              "\n";
    }
  }
  return text;
}

TEST(CadModel, ConcurrentEvaluationMatchesSerial) {
  auto box = LoadOk(Solid::kBoxWithHole, ModelFormat::kStep);
  ASSERT_NE(box, nullptr);
  auto patch = Load(ModelFormat::kNurbs, MultiSpanPatch(), "spans.nurbs");
  ASSERT_TRUE(patch.ok()) << patch.status();
  std::vector<Face> faces = box->faces();
  faces.push_back((*patch)->faces()[0]);
  const int n = 40;
  auto run = [&](std::vector<double>& out) {
    for (const Face& face : faces) {
      for (int i = 0; i < n; ++i) {
        for (int j = 0; j < n; ++j) {
          const SurfaceJet jet = face.surface().Jet((i + 0.5) / n, (j + 0.5) / n, 2);
          out.insert(out.end(), {jet.p.x, jet.fu.y, jet.fvv.z,
                                 face.Contains((i + 0.5) / n, (j + 0.5) / n) ? 1.0 : 0.0});
        }
      }
    }
  };
  std::vector<double> serial;
  run(serial);
  std::vector<std::vector<double>> parallel(4);
  std::vector<std::thread> threads;
  for (auto& out : parallel) threads.emplace_back([&] { run(out); });
  for (auto& t : threads) t.join();
  for (const auto& out : parallel) EXPECT_EQ(out, serial);
}

// The batch calls (one adaptor lease a batch) give Point's and Jet's values
// bit for bit, on every face type of the fixtures.
TEST(CadModel, BatchEvaluationEqualsPointByPoint) {
  std::vector<std::shared_ptr<const Model>> models = {
      LoadOk(Solid::kBoxWithHole, ModelFormat::kStep), LoadOk(Solid::kSphere, ModelFormat::kStep),
      LoadOk(Solid::kCylinder, ModelFormat::kIges),
      LoadOk(Solid::kTiltedConeAndTorus, ModelFormat::kStep)};
  auto patch = Load(ModelFormat::kNurbs, MultiSpanPatch(), "spans.nurbs");
  ASSERT_TRUE(patch.ok()) << patch.status();
  models.push_back(*patch);
  std::mt19937_64 rng(8);
  std::uniform_real_distribution<double> unit(0, 1);
  for (const auto& model : models) {
    ASSERT_NE(model, nullptr);
    for (const Face& face : model->faces()) {
      const Surface& surface = face.surface();
      std::vector<double> u(200), v(200), x(200), y(200), z(200);
      for (size_t i = 0; i < u.size(); ++i) u[i] = unit(rng), v[i] = unit(rng);
      u[0] = 0, v[0] = 1;
      surface.Points(u.data(), v.data(), u.size(), x.data(), y.data(), z.data());
      for (size_t i = 0; i < u.size(); ++i) {
        const Vec3 p = surface.Point(u[i], v[i]);
        ASSERT_EQ(std::memcmp(&p.x, &x[i], 8) | std::memcmp(&p.y, &y[i], 8) |
                      std::memcmp(&p.z, &z[i], 8),
                  0)
            << model->name() << " face " << face.index() << " sample " << i;
      }
      for (int order : {1, 2}) {
        std::vector<SurfaceJet> grid(7 * 5);
        surface.JetGrid(u.data(), 7, v.data(), 5, order, grid.data());
        for (int i = 0; i < 7; ++i) {
          for (int j = 0; j < 5; ++j) {
            const SurfaceJet one = surface.Jet(u[i], v[j], order);
            const SurfaceJet& g = grid[i * 5 + j];
            for (auto [a, b] : {std::pair{one.p, g.p}, {one.fu, g.fu}, {one.fv, g.fv},
                                {one.fuu, g.fuu}, {one.fuv, g.fuv}, {one.fvv, g.fvv}}) {
              ASSERT_EQ(std::memcmp(&a, &b, sizeof(Vec3)), 0)
                  << model->name() << " face " << face.index() << " order " << order;
            }
          }
        }
      }
    }
  }
}

// Planes, cylinders, cones, spheres and tori are evaluated from their closed forms (SLEEF's
// sines and cosines), within a few ulp of the kernel's values (glibc's): each
// fixture loaded with and without closed forms gives the same points and
// derivatives, within 1e-14 of the model's size (or the derivative's, where
// larger), at random parameters (inside the square and on its edges). A wrong
// formula is off by a fraction of the size.
TEST(CadModel, ClosedFormsMatchTheKernel) {
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> unit(0, 1);
  int closed = 0;
  double worst = 0;  // the largest difference seen, relative to its scale
  for (Solid solid : {Solid::kBoxWithHole, Solid::kTiltedBoxWithHole, Solid::kSphere,
                      Solid::kCylinder, Solid::kTiltedConeAndTorus}) {
    for (ModelFormat format : {ModelFormat::kStep, ModelFormat::kIges}) {
      auto fast = LoadOk(solid, format);
      LoadOptions options;
      options.closed_forms = false;
      auto kernel = Load(format, Bytes(solid, format), fixtures::SolidName(solid), options);
      ASSERT_TRUE(kernel.ok()) << kernel.status();
      ASSERT_NE(fast, nullptr);
      ASSERT_EQ(fast->faces().size(), (*kernel)->faces().size());
      for (size_t f = 0; f < fast->faces().size(); ++f) {
        const Face& a = fast->faces()[f];
        const Face& b = (*kernel)->faces()[f];
        EXPECT_FALSE(b.closed_form());
        const bool elementary = a.type() == FaceType::kPlane || a.type() == FaceType::kCylinder ||
                                a.type() == FaceType::kCone || a.type() == FaceType::kSphere ||
                                a.type() == FaceType::kTorus;
        if (format == ModelFormat::kStep) {
          EXPECT_EQ(a.closed_form(), elementary)
              << fixtures::SolidName(solid) << " face " << f << " " << FaceTypeName(a.type());
        }
        closed += a.closed_form();
        const double size = std::sqrt(fast->total_area()) + std::abs(a.centroid().x) +
                            std::abs(a.centroid().y) + std::abs(a.centroid().z);
        auto differ = [&](const Vec3& u, const Vec3& w) {
          const double scale =
              std::max({size, std::abs(w.x), std::abs(w.y), std::abs(w.z)});
          const double off =
              std::max({std::abs(u.x - w.x), std::abs(u.y - w.y), std::abs(u.z - w.z)}) / scale;
          worst = std::max(worst, off);
          return !(off <= 1e-14);
        };
        for (int k = 0; k < 3000; ++k) {
          const double s = k < 4 ? double(k / 2) : unit(rng), t = k < 4 ? double(k % 2) : unit(rng);
          const int order = 1 + k % 2;
          const SurfaceJet x = a.surface().Jet(s, t, order), y = b.surface().Jet(s, t, order);
          const Vec3 p = a.surface().Point(s, t), q = b.surface().Point(s, t);
          ASSERT_FALSE(differ(p, q)) << "face " << f << " at " << s << ", " << t;
          for (auto [u, w] : {std::pair{x.p, y.p}, {x.fu, y.fu}, {x.fv, y.fv}, {x.fuu, y.fuu},
                              {x.fuv, y.fuv}, {x.fvv, y.fvv}}) {
            ASSERT_FALSE(differ(u, w))
                << fixtures::SolidName(solid) << " face " << f << " order " << order << " at (" << s
                << ", " << t << ")";
          }
        }
      }
    }
  }
  EXPECT_GE(closed, 22) << "both boxes' eight faces, the sphere's, the cone's three and the "
                          "torus's, at least, in STEP";
  std::printf("closed forms against the kernel: worst difference %.3g of the scale\n", worst);
  auto cone = LoadOk(Solid::kTiltedConeAndTorus, ModelFormat::kStep);
  ASSERT_NE(cone, nullptr);
  std::map<FaceType, int> types;
  for (const Face& face : cone->faces()) types[face.type()] += face.closed_form();
  EXPECT_GE(types[FaceType::kCone], 1);
  EXPECT_GE(types[FaceType::kTorus], 1);
  EXPECT_GE(types[FaceType::kPlane], 2);
}

// Surface::Bound of every face kind the fixtures hold, evaluated from closed
// forms or through the kernel (planes, cylinders, cones, spheres and tori,
// also under a transformation; B-spline patches, rational and over several
// spans): every point of a random patch, on its edges and inside, lies in
// its box, and the box of a small patch is small (the hidden-mass check
// narrows on it).
TEST(CadModel, BoundsHoldEveryPointOfAPatchAndShrinkWithIt) {
  std::vector<std::shared_ptr<const Model>> models;
  for (Solid solid : {Solid::kBoxWithHole, Solid::kTiltedBoxWithHole, Solid::kSphere,
                      Solid::kCylinder, Solid::kTiltedConeAndTorus}) {
    for (bool closed : {true, false}) {
      LoadOptions options;
      options.closed_forms = closed;
      auto model = Load(ModelFormat::kStep, Bytes(solid, ModelFormat::kStep),
                        fixtures::SolidName(solid), options);
      ASSERT_TRUE(model.ok()) << model.status();
      models.push_back(*model);
    }
  }
  for (const std::string& text : {fixtures::NurbsPatchText(), MultiSpanPatch()}) {
    auto patch = Load(ModelFormat::kNurbs, text, "patch.nurbs");
    ASSERT_TRUE(patch.ok()) << patch.status();
    models.push_back(*patch);
  }
  std::mt19937_64 rng(12);
  std::uniform_real_distribution<double> unit(0, 1);
  int faces = 0;
  for (const auto& model : models) {
    for (const Face& face : model->faces()) {
      ++faces;
      const Surface& surface = face.surface();
      const std::optional<Box3> whole = surface.Bound(0, 1, 0, 1);
      ASSERT_TRUE(whole.has_value()) << model->name() << " face " << face.index();
      const double size = Norm(whole->hi - whole->lo);
      for (int depth : {0, 2, 5, 9, 14}) {
        const double h = std::ldexp(1.0, -depth);
        for (int trial = 0; trial < 6; ++trial) {
          const double u0 = std::floor(unit(rng) / h) * h, v0 = std::floor(unit(rng) / h) * h;
          const double u1 = std::min(1.0, u0 + h), v1 = std::min(1.0, v0 + h);
          const std::optional<Box3> box = surface.Bound(u0, u1, v0, v1);
          ASSERT_TRUE(box.has_value());
          auto inside = [&](double u, double v) {
            const Vec3 p = surface.Point(u, v);
            EXPECT_TRUE(p.x >= box->lo.x && p.x <= box->hi.x && p.y >= box->lo.y &&
                        p.y <= box->hi.y && p.z >= box->lo.z && p.z <= box->hi.z)
                << model->name() << " face " << face.index() << " cell [" << u0 << ", " << u1
                << "] x [" << v0 << ", " << v1 << "] at (" << u << ", " << v << ")";
          };
          for (int i = 0; i <= 4; ++i) {
            for (int j = 0; j <= 4; ++j) inside(u0 + (u1 - u0) * i / 4, v0 + (v1 - v0) * j / 4);
          }
          for (int k = 0; k < 20; ++k)
            inside(u0 + (u1 - u0) * unit(rng), v0 + (v1 - v0) * unit(rng));
          if (depth == 14) {
            EXPECT_LT(Norm(box->hi - box->lo), 1e-3 * size)
                << model->name() << " face " << face.index();
          }
        }
      }
    }
  }
  EXPECT_GE(faces, 40);
}

TEST(CadModel, LoadingTwiceGivesTheSameFaces) {
  for (ModelFormat format : {ModelFormat::kStep, ModelFormat::kIges}) {
    auto a = LoadOk(Solid::kBoxWithHole, format), b = LoadOk(Solid::kBoxWithHole, format);
    ASSERT_NE(a, nullptr);
    ASSERT_NE(b, nullptr);
    ASSERT_EQ(a->faces().size(), b->faces().size());
    EXPECT_EQ(a->curve_order(), b->curve_order());
    for (size_t i = 0; i < a->faces().size(); ++i) {
      const Face &fa = a->faces()[i], &fb = b->faces()[i];
      EXPECT_EQ(fa.type(), fb.type());
      EXPECT_EQ(fa.area(), fb.area());
      EXPECT_EQ(fa.parameter_box().u0, fb.parameter_box().u0);
      EXPECT_EQ(fa.parameter_box().v1, fb.parameter_box().v1);
      EXPECT_EQ(fa.surface().Point(0.3, 0.7), fb.surface().Point(0.3, 0.7));
    }
  }
}

TEST(CadModel, CurveOrderIsAPermutationAndDescriptionListsFaces) {
  auto model = LoadOk(Solid::kBoxWithHole, ModelFormat::kStep);
  ASSERT_NE(model, nullptr);
  std::vector<int> order = model->curve_order();
  std::sort(order.begin(), order.end());
  for (size_t i = 0; i < order.size(); ++i) EXPECT_EQ(order[i], static_cast<int>(i));
  const std::string text = DescribeModel(*model);
  EXPECT_NE(text.find("box_with_hole"), std::string::npos) << text;
  EXPECT_NE(text.find("cylinder"), std::string::npos) << text;
  EXPECT_NE(text.find("plane"), std::string::npos) << text;
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'),
            static_cast<long>(model->faces().size()) + 3)
      << text;
}

TEST(CadNurbs, QuarterCylinderPatch) {
  auto model = Load(ModelFormat::kNurbs, fixtures::NurbsPatchText(), "quarter.nurbs");
  ASSERT_TRUE(model.ok()) << model.status();
  ASSERT_EQ((*model)->faces().size(), 1u);
  const Face& face = (*model)->faces()[0];
  const double r = fixtures::kPatchRadius, h = fixtures::kPatchHeight;
  EXPECT_EQ(face.type(), FaceType::kBSpline);
  EXPECT_FALSE(face.trimmed());
  EXPECT_NEAR(face.area(), kPi / 2 * r * h, 1e-6);
  for (double s : {0.0, 0.25, 0.5, 1.0}) {
    for (double t : {0.0, 0.6}) {
      const Vec3 p = face.surface().Point(s, t);
      EXPECT_NEAR(std::hypot(p.x, p.y), r, 1e-12) << "the weights make an exact circle";
      EXPECT_NEAR(p.z, t * h, 1e-12);
    }
  }
  ExpectJetMatchesDifferences(face.surface(), r + h, "nurbs");
  EXPECT_NEAR(ClassifiedArea(face, 200), face.area(), 1e-3 * face.area());
}

// The example in docs/NURBS_FORMAT.md loads, and its corner poles lie on the
// surface (clamped ends interpolate the corners).
TEST(CadNurbs, DocumentedExampleLoads) {
  std::ifstream in(std::string(SFC_SOURCE_DIR) + "/docs/NURBS_FORMAT.md");
  ASSERT_TRUE(in) << "docs/NURBS_FORMAT.md";
  std::stringstream doc;
  doc << in.rdbuf();
  const std::string text = doc.str();
  const size_t begin = text.find("```text\n"), end = text.find("```", begin + 8);
  ASSERT_NE(begin, std::string::npos);
  ASSERT_NE(end, std::string::npos);
  auto model =
      Load(ModelFormat::kNurbs, text.substr(begin + 8, end - begin - 8), "NURBS_FORMAT.md");
  ASSERT_TRUE(model.ok()) << model.status();
  const Face& face = (*model)->faces()[0];
  ExpectNear(face.surface().Point(0, 0), Vec3{0, 0, 0}, 1e-12, "corner (0, 0)");
  ExpectNear(face.surface().Point(1, 1), Vec3{4, 2, 0}, 1e-12, "corner (1, 1)");
  ExpectNear(face.surface().Point(0, 1), Vec3{0, 2, 0}, 1e-12, "corner (0, 1)");
  ExpectJetMatchesDifferences(face.surface(), 4, "documented example");
  EXPECT_GT(face.area(), 8.0) << "a wavy 4 x 2 sheet is larger than its shadow";
}

void ExpectInvalid(ModelFormat format, const std::string& bytes, const std::string& name,
                   const std::string& needle) {
  auto model = Load(format, bytes, name);
  ASSERT_FALSE(model.ok()) << name << " loaded";
  EXPECT_EQ(model.status().code(), absl::StatusCode::kInvalidArgument) << model.status();
  EXPECT_NE(model.status().message().find(name), std::string::npos) << model.status();
  EXPECT_NE(model.status().message().find(needle), std::string::npos) << model.status();
}

TEST(CadErrors, MalformedStepAndIges) {
  const std::string& step = Bytes(Solid::kBoxWithHole, ModelFormat::kStep);
  const std::string& iges = Bytes(Solid::kBoxWithHole, ModelFormat::kIges);
  ExpectInvalid(ModelFormat::kStep, step.substr(0, step.size() / 2), "cut.step", "truncated");
  ExpectInvalid(ModelFormat::kStep, step.substr(0, step.size() - 40), "cut_end.step", "truncated");
  ExpectInvalid(ModelFormat::kStep, "hello", "hello.step", "not a STEP file");
  ExpectInvalid(ModelFormat::kStep, "", "empty_bytes.step", "not a STEP file");
  ExpectInvalid(ModelFormat::kIges, iges.substr(0, iges.size() / 2), "cut.iges", "truncated");
  ExpectInvalid(ModelFormat::kIges, step, "step_as.iges", "not an IGES file");
  const std::string empty_model =
      "ISO-10303-21;\nHEADER;\nFILE_DESCRIPTION(('empty'),'2;1');\n"
      "FILE_NAME('empty.step','2026-01-01T00:00:00',(''),(''),'','','');\n"
      "FILE_SCHEMA(('AUTOMOTIVE_DESIGN { 1 0 10303 214 1 1 1 1 }'));\nENDSEC;\nDATA;\nENDSEC;\n"
      "END-ISO-10303-21;\n";
  ExpectInvalid(ModelFormat::kStep, empty_model, "empty.step", "empty model");
  for (ModelFormat format : {ModelFormat::kStep, ModelFormat::kIges}) {
    ExpectInvalid(format, Bytes(Solid::kEdgeOnly, format), "edge_only", "no faces");
  }
  // Garbage inside a well-framed file.
  std::string mangled = step;
  const size_t data = mangled.find("DATA;");
  ASSERT_NE(data, std::string::npos);
  for (size_t i = data + 200; i < mangled.size() - 2000; i += 97) mangled[i] = '(';
  auto model = Load(ModelFormat::kStep, mangled, "mangled.step");
  if (!model.ok()) {
    EXPECT_EQ(model.status().code(), absl::StatusCode::kInvalidArgument);
    EXPECT_NE(model.status().message().find("mangled.step"), std::string::npos) << model.status();
  }
}

// Non-finite coordinates in a STEP file: an overflowing number and a NaN
// token in the sphere's centre.
TEST(CadErrors, NonFiniteStepCoordinates) {
  const std::string& step = Bytes(Solid::kSphere, ModelFormat::kStep);
  const std::string centre = "CARTESIAN_POINT('',(0.,0.,0.))";
  ASSERT_NE(step.find(centre), std::string::npos);
  std::string text = step;
  text.replace(text.find(centre), centre.size(), "CARTESIAN_POINT('',(1.E999,0.,0.))");
  ExpectInvalid(ModelFormat::kStep, text, "centre_1.E999.step", "non-finite");
  // NaN is no STEP number: the reader's syntax error is passed on, with its line.
  text = step;
  text.replace(text.find(centre), centre.size(), "CARTESIAN_POINT('',(NaN,0.,0.))");
  ExpectInvalid(ModelFormat::kStep, text, "centre_NaN.step", "Incorrect syntax");
}

// IGES goes through a temporary file: it is private to Load and gone after,
// whether the read succeeds or fails.
TEST(CadErrors, IgesTemporaryFileIsRemoved) {
  const std::string dir = ::testing::TempDir() + "/cad_iges_tmp";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const char* old = std::getenv("TMPDIR");
  const std::string saved = old ? old : "";
  setenv("TMPDIR", dir.c_str(), 1);
  const std::string& iges = Bytes(Solid::kCylinder, ModelFormat::kIges);
  EXPECT_TRUE(Load(ModelFormat::kIges, iges, "cylinder.iges").ok());
  // Mangled records: the kernel's IGES reader dereferences a null loop here
  // (a fault that Load turns into an error).
  std::string broken = iges;
  broken.replace(broken.size() / 3, 400, std::string(400, '('));
  auto model = Load(ModelFormat::kIges, broken, "broken.iges");
  ASSERT_FALSE(model.ok());
  EXPECT_EQ(model.status().code(), absl::StatusCode::kInvalidArgument) << model.status();
  EXPECT_NE(model.status().message().find("broken.iges"), std::string::npos) << model.status();
  if (old) {
    setenv("TMPDIR", saved.c_str(), 1);
  } else {
    unsetenv("TMPDIR");
  }
  EXPECT_TRUE(std::filesystem::is_empty(dir)) << "a temporary file was left in " << dir;
}

TEST(CadErrors, ByteLimitIsResourceExhausted) {
  const std::string& step = Bytes(Solid::kSphere, ModelFormat::kStep);
  LoadOptions options;
  options.max_bytes = step.size() - 1;
  auto model = Load(ModelFormat::kStep, step, "big.step", options);
  ASSERT_FALSE(model.ok());
  EXPECT_EQ(model.status().code(), absl::StatusCode::kResourceExhausted);
  EXPECT_NE(model.status().message().find("big.step"), std::string::npos) << model.status();
  options.max_bytes = step.size();
  EXPECT_TRUE(Load(ModelFormat::kStep, step, "fits.step", options).ok());
}

TEST(CadErrors, MalformedNurbs) {
  const std::string good = fixtures::NurbsPatchText();
  auto with = [&](const std::string& from, const std::string& to) {
    std::string text = absl::StrReplaceAll(good, {{from, to}});
    EXPECT_NE(text, good) << "the edit '" << from << "' did not apply";
    return text;
  };
  ExpectInvalid(ModelFormat::kNurbs, with("knots_u 0 0 0 1 1 1", "knots_u 0 0 1 1 1"),
                "short.nurbs", "knots");
  ExpectInvalid(ModelFormat::kNurbs, with("knots_u 0 0 0 1 1 1", "knots_u 0 0 0 1 0.5 1"),
                "decreasing.nurbs", "decreases");
  ExpectInvalid(ModelFormat::kNurbs, with("knots_u 0 0 0 1 1 1", "knots_u 0 0 1 1 1 1"),
                "unclamped.nurbs", "clamped");
  ExpectInvalid(ModelFormat::kNurbs, with("knots_v 0 0 1 1", "knots_v 0 0 0 0"), "flat.nurbs",
                "empty");
  ExpectInvalid(ModelFormat::kNurbs, with("degree 2 1", "degree 0 1"), "degree.nurbs", "degree");
  ExpectInvalid(ModelFormat::kNurbs, with("count 3 2", "count 4 2"), "count.nurbs", "knots");
  ExpectInvalid(ModelFormat::kNurbs, with("pole 2 0 3 1", "pole nan 0 3 1"), "nan.nurbs", "NaN");
  ExpectInvalid(ModelFormat::kNurbs, with("pole 2 0 3 1", "pole 2 0 inf 1"), "inf.nurbs",
                "NaN or infinite");
  ExpectInvalid(ModelFormat::kNurbs, with("pole 2 0 3 1", "pole 2 0 3 0"), "weight.nurbs",
                "weight");
  ExpectInvalid(ModelFormat::kNurbs, with("pole 2 0 3 1\n", ""), "missing.nurbs", "control points");
  ExpectInvalid(ModelFormat::kNurbs, with("knots_v", "knots_w"), "keyword.nurbs",
                "unknown keyword");
  ExpectInvalid(ModelFormat::kNurbs, with("sfcsampler-nurbs 1", "nurbs 2"), "header.nurbs",
                "first line");
  ExpectInvalid(ModelFormat::kNurbs, "", "nothing.nurbs", "empty");
  // An interior knot of multiplicity above the degree.
  const std::string cubic =
      "sfcsampler-nurbs 1\ndegree 1 1\ncount 3 2\nknots_u 0 0 0.5 0.5 1\nknots_v 0 0 1 1\n"
      "pole 0 0 0\npole 0 1 0\npole 1 0 0\npole 1 1 0\npole 2 0 0\npole 2 1 0\n";
  ExpectInvalid(ModelFormat::kNurbs, cubic, "multiplicity.nurbs",
                "multiplicity 2, above the degree 1");
}

TEST(CadFormat, ParsesNames) {
  EXPECT_EQ(*ParseModelFormat("STEP"), ModelFormat::kStep);
  EXPECT_EQ(*ParseModelFormat("stp"), ModelFormat::kStep);
  EXPECT_EQ(*ParseModelFormat("igs"), ModelFormat::kIges);
  EXPECT_EQ(*ParseModelFormat("nurbs"), ModelFormat::kNurbs);
  EXPECT_EQ(ParseModelFormat("stl").status().code(), absl::StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace sfc::cad
