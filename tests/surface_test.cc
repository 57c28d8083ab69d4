// Closed-form jets of the built-in surfaces agree with high-order finite
// differences of their positions (away from singular lines), and the
// superellipsoid's jet reports its singular lines as infinite.
#include <cmath>
#include <cstring>
#include <memory>
#include <random>
#include <vector>

#include "core/builtin_surfaces.h"
#include "core/superellipsoid_internal.h"
#include "core/vector_math.h"
#include "gtest/gtest.h"

namespace sfc {
namespace {

// 4th-order central differences of Point.
Vec3 Du(const Surface& s, double u, double v, double h) {
  return (s.Point(u - 2 * h, v) - s.Point(u + 2 * h, v) +
          (s.Point(u + h, v) - s.Point(u - h, v)) * 8) *
         (1 / (12 * h));
}
Vec3 Dv(const Surface& s, double u, double v, double h) {
  return (s.Point(u, v - 2 * h) - s.Point(u, v + 2 * h) +
          (s.Point(u, v + h) - s.Point(u, v - h)) * 8) *
         (1 / (12 * h));
}

void ExpectNear(const Vec3& a, const Vec3& b, double tol, const char* what, double u, double v) {
  const double scale = 1 + Norm(b);
  EXPECT_LT(Norm(a - b), tol * scale) << what << " at (" << u << ", " << v << ")";
}

void ExpectJetMatchesDifferences(const Surface& s) {
  // Points a tenth away from the superellipsoid's singular lines, where
  // finite differences of a |c|^(1/3) profile are still accurate.
  for (double u : {0.2, 0.33, 0.61, 0.8}) {
    for (double v : {0.1, 0.15, 0.4, 0.6, 0.9}) {
      const SurfaceJet j = s.Jet(u, v, 2);
      const double h = 1e-4;
      ExpectNear(j.p, s.Point(u, v), 1e-14, "p", u, v);
      ExpectNear(j.fu, Du(s, u, v, h), 1e-7, "fu", u, v);
      ExpectNear(j.fv, Dv(s, u, v, h), 1e-7, "fv", u, v);
      const double k = 1e-3;
      ExpectNear(j.fuu, (Du(s, u + k, v, h) - Du(s, u - k, v, h)) * (1 / (2 * k)), 1e-3, "fuu", u,
                 v);
      ExpectNear(j.fvv, (Dv(s, u, v + k, h) - Dv(s, u, v - k, h)) * (1 / (2 * k)), 1e-3, "fvv", u,
                 v);
      ExpectNear(j.fuv, (Du(s, u, v + k, h) - Du(s, u, v - k, h)) * (1 / (2 * k)), 1e-3, "fuv", u,
                 v);
      // The grid version is the same jet.
      double us[1] = {u}, vs[1] = {v};
      SurfaceJet g;
      s.JetGrid(us, 1, vs, 1, 2, &g);
      EXPECT_EQ(g.fu.x, j.fu.x);
      EXPECT_EQ(g.fvv.y, j.fvv.y);
    }
  }
}

TEST(BuiltinSurfaces, SuperellipsoidJetIsExact) {
  for (double e : {1.0 / 3, 1.0, 2.5}) {
    for (bool reparam : {false, true}) {
      SCOPED_TRACE(testing::Message() << "e = " << e << " reparam = " << reparam);
      ExpectJetMatchesDifferences(*MakeSuperellipsoid(e, reparam));
    }
  }
}

TEST(BuiltinSurfaces, OtherJetsAreExact) {
  ExpectJetMatchesDifferences(*MakeSphere(1));
  ExpectJetMatchesDifferences(*MakeTorus(1, 0.3));
  ExpectJetMatchesDifferences(*MakeEightSurface());
  ExpectJetMatchesDifferences(*MakeMonkeySaddle());
  ExpectJetMatchesDifferences(*MakeWhitneyUmbrella());
}

std::vector<std::unique_ptr<Surface>> EveryBuiltin() {
  std::vector<std::unique_ptr<Surface>> surfaces;
  surfaces.push_back(MakePlane());
  surfaces.push_back(MakeSphere(1.5));
  surfaces.push_back(MakeTorus(1, 0.3));
  surfaces.push_back(MakeEightSurface());
  surfaces.push_back(MakeMonkeySaddle());
  surfaces.push_back(MakeWhitneyUmbrella());
  surfaces.push_back(MakeSuperellipsoid(1.0 / 3, false));
  surfaces.push_back(MakeSuperellipsoid(0.5, true));
  surfaces.push_back(MakeSuperellipsoid(1, false));  // e = 1: the jets' other branch
  return surfaces;
}

// JetGrid is Jet at every node, in every bit of every field (the tree build
// uses the grid; Jet is the reference): every grid size from 1 x 1 to
// 17 x 17 (short batches' padded tails, and the point-by-point fallback
// past 16), orders 1 and 2, every built-in.
TEST(BuiltinSurfaces, JetGridIsJetBitForBit) {
  const std::vector<std::unique_ptr<Surface>> surfaces = EveryBuiltin();
  for (const auto& surface : surfaces) {
    for (int n = 1; n <= 17; ++n) {
      std::vector<double> us(n), vs(n);
      for (int i = 0; i < n; ++i) us[i] = (i + 0.37) / (n + 1), vs[i] = (n - i + 0.11) / (n + 2);
      for (int order : {1, 2}) {
        std::vector<SurfaceJet> grid(n * n);
        surface->JetGrid(us.data(), n, vs.data(), n, order, grid.data());
        for (int i = 0; i < n; ++i) {
          for (int j = 0; j < n; ++j) {
            const SurfaceJet want = surface->Jet(us[i], vs[j], order);
            ASSERT_EQ(std::memcmp(&grid[i * n + j], &want, sizeof want), 0)
                << "n = " << n << " order " << order << " at (" << us[i] << ", " << vs[j] << ")";
          }
        }
      }
    }
  }
}

// The batch call is Point, bit for bit, on every built-in (including the
// superellipsoid's singular lines, where both give the same infinities).
TEST(BuiltinSurfaces, PointsIsPointBitForBit) {
  const std::vector<std::unique_ptr<Surface>> surfaces = EveryBuiltin();
  std::vector<double> u, v;
  for (int i = 0; i <= 40; ++i) {
    for (int j = 0; j <= 40; ++j) u.push_back(i / 40.0), v.push_back(j / 40.0);
  }
  const size_t n = u.size();
  for (const auto& surface : surfaces) {
    std::vector<double> x(n), y(n), z(n);
    surface->Points(u.data(), v.data(), n, x.data(), y.data(), z.data());
    for (size_t i = 0; i < n; ++i) {
      const Vec3 p = surface->Point(u[i], v[i]);
      const double got[3] = {x[i], y[i], z[i]}, want[3] = {p.x, p.y, p.z};
      ASSERT_EQ(std::memcmp(got, want, sizeof(got)), 0) << "at (" << u[i] << ", " << v[i] << ")";
    }
  }
}

// The superellipsoid's vector kernels (AVX2, AVX-512F: those this CPU runs)
// are Point bit for bit: every shape's branches (the cube root and Pow,
// plain and reparameterised angles), random parameters and those on and
// beside the quarter turns (the angles' pieces and roundings, the singular
// lines, -0); a block with a parameter outside [0, 1] stops the kernel
// there, and the batch call still gives Point's bits for it.
TEST(BuiltinSurfaces, SuperellipsoidVectorKernelsArePointBitForBit) {
  using superellipsoid_internal::Shape;
  std::vector<double> u, v;
  std::mt19937_64 random(7);
  std::uniform_real_distribution<double> unit(0, 1);
  std::vector<double> special = {0.0, -0.0, 1.0, math::kBelowOne};
  for (int k = 1; k < 16; ++k) {
    const double at = k / 16.0;
    special.insert(special.end(), {at, std::nextafter(at, 0.0), std::nextafter(at, 1.0)});
  }
  for (double a : special) {
    for (double b : special) u.push_back(a), v.push_back(b);
  }
  for (int i = 0; i < 4000; ++i) u.push_back(unit(random)), v.push_back(unit(random));
  constexpr size_t kBlock = superellipsoid_internal::kBlock;
  u.resize(u.size() / kBlock * kBlock), v.resize(u.size());
  const size_t n = u.size();
  struct Kernel {
    math::VectorPath path;
    size_t (*points)(Shape, const double*, const double*, size_t, double*, double*, double*);
  };
  const Kernel kernels[] = {{math::VectorPath::kAvx2, superellipsoid_internal::PointsAvx2},
                            {math::VectorPath::kAvx512, superellipsoid_internal::PointsAvx512}};
  for (const Shape shape : {Shape{1.0 / 3, false}, Shape{1.0 / 3, true}, Shape{0.25, false},
                            Shape{0.5, true}, Shape{1, false}, Shape{3, true}}) {
    const auto surface = MakeSuperellipsoid(shape.e, shape.reparam);
    for (const Kernel& kernel : kernels) {
      if (!math::Runs(kernel.path)) continue;
      std::vector<double> x(n), y(n), z(n);
      ASSERT_EQ(kernel.points(shape, u.data(), v.data(), n, x.data(), y.data(), z.data()), n);
      for (size_t i = 0; i < n; ++i) {
        const Vec3 p = surface->Point(u[i], v[i]);
        const double got[3] = {x[i], y[i], z[i]}, want[3] = {p.x, p.y, p.z};
        ASSERT_EQ(std::memcmp(got, want, sizeof(got)), 0)
            << math::VectorPathName(kernel.path) << " e = " << shape.e << " reparam "
            << shape.reparam << " at (" << u[i] << ", " << v[i] << ")";
      }
      // A parameter outside [0, 1] in point 200: the kernel stops at its block.
      std::vector<double> w = v;
      w[200] = 1.5;
      EXPECT_EQ(kernel.points(shape, u.data(), w.data(), n, x.data(), y.data(), z.data()),
                200 / kBlock * kBlock);
    }
    // The batch call with parameters outside [0, 1] here and there.
    std::vector<double> w = u;
    for (size_t i = 5; i < n; i += 97) w[i] = i % 2 ? -0.25 : 1.75;
    std::vector<double> x(n), y(n), z(n);
    surface->Points(w.data(), v.data(), n, x.data(), y.data(), z.data());
    for (size_t i = 0; i < n; ++i) {
      const Vec3 p = surface->Point(w[i], v[i]);
      const double got[3] = {x[i], y[i], z[i]}, want[3] = {p.x, p.y, p.z};
      ASSERT_EQ(std::memcmp(got, want, sizeof(got)), 0) << "at (" << w[i] << ", " << v[i] << ")";
    }
  }
}

TEST(BuiltinSurfaces, SuperellipsoidSingularLinesAreInfiniteNotNaNPositions) {
  auto s = MakeSuperellipsoid(1.0 / 3, false);
  // u = 1/2 is the equator, where sin(angle) = 0: the area element is infinite.
  const SurfaceJet j = s->Jet(0.5, 0.3, 1);
  EXPECT_TRUE(std::isfinite(j.p.x) && std::isfinite(j.p.z));
  EXPECT_TRUE(std::isinf(Norm(Cross(j.fu, j.fv))));
}

}  // namespace
}  // namespace sfc
