// Every vector path of core/vector_math.h that this CPU runs gives the scalar
// reference's bits, over arguments the samplers use ([0, 2]: pi u and 2 pi v)
// and beyond, with every tail a batch leaves (one padded vector, or a single
// value through the scalar path); and the values are sin and cos of pi x.
#include "core/vector_math.h"

#include <cfloat>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <random>
#include <set>
#include <string_view>
#include <utility>
#include <vector>

#include <sleef.h>

#include "core/slope_batch.h"
#include "gtest/gtest.h"

namespace sfc::math {
namespace {

std::vector<double> Arguments() {
  std::vector<double> x = {0,         0.5,     1,           1.5,  2,         -0.5,
                           0x1p-1074, 0x1p-30, 1 - 0x1p-53, 0.25, 1e6 + 0.25};
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> unit(0, 2), wide(-1e3, 1e3);
  for (int i = 0; i < 100000; ++i) x.push_back(unit(rng));
  for (int i = 0; i < 10000; ++i) x.push_back(wide(rng));
  for (int i = 0; i < 10000; ++i) x.push_back(std::ldexp(unit(rng), -static_cast<int>(rng() % 60)));
  x.push_back(0.75);  // an odd length: every path has a tail
  return x;
}

bool SameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }
// The same bits, or both NaN (sin of infinity: SLEEF's portable C and its
// vector code set different sign bits; a sample there is rejected anyway).
bool SameValue(double a, double b) { return SameBits(a, b) || (std::isnan(a) && std::isnan(b)); }

// Each path is its own instruction set, by CPUID; the default is the widest
// this CPU runs; kAvx2 takes the AVX builds where a function has no AVX2 one.
TEST(VectorMath, PathsAreTheCpusInstructionSets) {
  EXPECT_TRUE(Runs(VectorPath::kScalar) && Runs(VectorPath::kSse2));
  EXPECT_EQ(Runs(VectorPath::kAvx), __builtin_cpu_supports("avx") != 0);
  EXPECT_EQ(Runs(VectorPath::kAvx2), __builtin_cpu_supports("avx2") != 0);
  EXPECT_EQ(Runs(VectorPath::kAvx512), __builtin_cpu_supports("avx512f") != 0);
  ASSERT_TRUE(Runs(BestVectorPath()));
  if (std::getenv("SFCSAMPLER_VECTOR_PATH") == nullptr) {
    for (VectorPath path : kVectorPaths) {
      if (static_cast<int>(path) > static_cast<int>(BestVectorPath())) {
        EXPECT_FALSE(Runs(path)) << VectorPathName(path);
      }
    }
  }
  std::set<std::string_view> names;
  for (VectorPath path : kVectorPaths) {
    names.insert(VectorPathName(path));
    EXPECT_EQ(WithoutAvx2(path), path == VectorPath::kAvx2 ? VectorPath::kAvx : path);
  }
  EXPECT_EQ(names, (std::set<std::string_view>{"scalar", "sse2", "avx", "avx2", "avx512f"}));
}

TEST(VectorMath, EveryPathGivesTheScalarBits) {
  const std::vector<double> x = Arguments();
  std::vector<double> s0(x.size()), c0(x.size());
  SinCosPiOn(VectorPath::kScalar, x.data(), x.size(), s0.data(), c0.data());
  int paths = 0;
  for (VectorPath path : kVectorPaths) {
    if (path == VectorPath::kScalar || !Runs(path)) continue;
    ++paths;
    for (size_t offset : {0, 1, 3}) {  // unaligned starts and every tail length
      std::vector<double> s(x.size() - offset), c(x.size() - offset);
      SinCosPiOn(path, x.data() + offset, s.size(), s.data(), c.data());
      for (size_t i = 0; i < s.size(); ++i) {
        ASSERT_TRUE(SameBits(s[i], s0[i + offset]) && SameBits(c[i], c0[i + offset]))
            << VectorPathName(path) << " x = " << x[i + offset];
      }
    }
  }
  EXPECT_GE(paths, 1);
  std::vector<double> s(x.size()), c(x.size());
  SinCosPi(x.data(), x.size(), s.data(), c.data());
  for (size_t i = 0; i < x.size(); ++i) {
    ASSERT_TRUE(SameBits(s[i], s0[i]) && SameBits(c[i], c0[i]));
    const SinCos one = SinCosPi(x[i]);  // the one-value function too
    ASSERT_TRUE(SameBits(one.sin, s0[i]) && SameBits(one.cos, c0[i])) << x[i];
  }
}

// Short batches (a tree build's 3 x 3 grids) end in a tail of 1 to 7
// values, computed as one more zero-padded vector: every length, from every
// start, on every path gives the scalar bits.
TEST(VectorMath, EveryShortBatchGivesTheScalarBits) {
  const std::vector<double> x = Arguments();
  for (VectorPath path : kVectorPaths) {
    if (!Runs(path)) continue;
    for (size_t start = 0; start + 17 < 2000; start += 17) {
      for (size_t n = 1; n <= 17; ++n) {
        double s[17], c[17];
        SinCosPiOn(path, x.data() + start, n, s, c);
        for (size_t i = 0; i < n; ++i) {
          const SinCos one = SinCosPi(x[start + i]);
          ASSERT_TRUE(SameBits(s[i], one.sin) && SameBits(c[i], one.cos))
              << VectorPathName(path) << " n = " << n << " x = " << x[start + i];
        }
      }
    }
  }
}

// The one-value sin, cos and pow give SLEEF's portable scalar bits.
TEST(VectorMath, OneValueFunctionsGiveThePortableBits) {
  for (double x : Arguments()) {
    const SinCos r = SinCosOf(x);
    const Sleef_double_2 e = Sleef_cinz_sincosd1_u10purec(x);
    ASSERT_TRUE(SameBits(r.sin, e.x) && SameBits(r.cos, e.y)) << x;
    const double y = 0.3 + std::fabs(std::fmod(x, 3.0));
    ASSERT_TRUE(SameBits(Pow(std::fabs(x), y), Sleef_cinz_powd1_u10purec(std::fabs(x), y))) << x;
  }
}

// The batch SinCosOf and Pow (the superellipsoid's and expressions' points)
// give the one-value functions' bits on every path, every start and length.
TEST(VectorMath, SinCosOfAndPowBatchesGiveTheScalarBits) {
  std::vector<double> x = Arguments();
  for (double& a : x) a = std::fabs(a);  // pow's bases: the superellipsoid's |cos|, |sin|
  x.push_back(0);
  x.push_back(INFINITY);
  for (double y : {1.0 / 3, 0.1, 2.5, -2.0 / 3}) {
    for (VectorPath path : kVectorPaths) {
      if (!Runs(path)) continue;
      for (size_t start : {0, 1, 3}) {
        for (size_t n : {x.size() - start, size_t{1}, size_t{2}, size_t{7}, size_t{13}}) {
          std::vector<double> s(n), c(n), p(n);
          SinCosOfOn(path, x.data() + start, n, s.data(), c.data());
          PowOn(path, x.data() + start, y, n, p.data());
          for (size_t i = 0; i < n; ++i) {
            const double a = x[start + i];
            const SinCos one = SinCosOf(a);
            ASSERT_TRUE(SameValue(s[i], one.sin) && SameValue(c[i], one.cos))
                << VectorPathName(path) << " x = " << a;
            ASSERT_TRUE(SameBits(p[i], Pow(a, y))) << VectorPathName(path) << " x = " << a;
          }
        }
      }
    }
  }
  std::vector<double> s(x.size()), c(x.size()), p(x.size());
  SinCosOf(x.data(), x.size(), s.data(), c.data());
  Pow(x.data(), 0.25, x.size(), p.data());
  for (size_t i = 0; i < x.size(); ++i) {
    ASSERT_TRUE(SameValue(s[i], SinCosOf(x[i]).sin) && SameBits(p[i], Pow(x[i], 0.25)));
  }
}

// The batch Cbrt (the superellipsoid's default powers) gives the one-value
// function's bits on every path, every start and length, and the cube root
// within 3.5 ulp, odd in x.
TEST(VectorMath, CbrtBatchesGiveTheScalarBitsAndCubeRoots) {
  std::vector<double> x = Arguments();
  x.push_back(0);
  x.push_back(-0.0);
  x.push_back(INFINITY);
  for (VectorPath path : kVectorPaths) {
    if (!Runs(path)) continue;
    for (size_t start : {0, 1, 3}) {
      for (size_t n : {x.size() - start, size_t{1}, size_t{2}, size_t{7}, size_t{13}}) {
        std::vector<double> r(n);
        CbrtOn(path, x.data() + start, n, r.data());
        for (size_t i = 0; i < n; ++i) {
          ASSERT_TRUE(SameBits(r[i], Cbrt(x[start + i])))
              << VectorPathName(path) << " x = " << x[start + i];
        }
      }
    }
  }
  for (double a : x) {
    const double r = Cbrt(a), e = std::cbrt(a);
    ASSERT_TRUE(SameBits(Cbrt(-a), -r)) << a;
    // 3.5 ulp from the cube root, and glibc's cbrt within 1 ulp of it.
    const double ulp = std::ldexp(DBL_EPSILON, std::ilogb(e));
    if (std::isfinite(a) && a != 0) ASSERT_LE(std::fabs(r - e), 4.5 * ulp) << a;
  }
  EXPECT_EQ(Cbrt(8.0), 2.0);
  EXPECT_EQ(Cbrt(INFINITY), INFINITY);
}

TEST(VectorMath, ValuesAreSineAndCosineOfPiX) {
  for (double x : Arguments()) {
    if (std::fabs(x) > 4) continue;
    const SinCos r = SinCosPi(x);
    const long double a = 3.141592653589793238462643383279502884L * x;
    // Within 3.5 ulp of values of magnitude at most 1.
    EXPECT_NEAR(r.sin, static_cast<double>(std::sin(a)), 3.5 * DBL_EPSILON / 2) << x;
    EXPECT_NEAR(r.cos, static_cast<double>(std::cos(a)), 3.5 * DBL_EPSILON / 2) << x;
  }
  // Exact where sin and cos are 0 or +-1.
  EXPECT_EQ(SinCosPi(1).sin, 0);
  EXPECT_EQ(SinCosPi(0.5).cos, 0);
  EXPECT_EQ(SinCosPi(2).cos, 1);
  const SinCos a = SinCosOf(0.3);
  EXPECT_NEAR(a.sin, std::sin(0.3), 1e-16);
  EXPECT_NEAR(a.cos, std::cos(0.3), 1e-16);
  EXPECT_NEAR(Pow(2.5, 1.0 / 3), std::cbrt(2.5), 1e-15);
  EXPECT_EQ(Pow(0, 0.5), 0);
}

// The placement's vectorised slope pass (core/slope_batch.h) gives the
// scalar code's bits on every path this CPU runs, for both ways of scaling
// the cell centres, at every tail length.
TEST(SlopeBatch, EveryPathGivesTheScalarBits) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> unit(0, 1);
  const size_t n = 1001;
  std::vector<double> c(n), p(n), q(n);
  for (size_t i = 0; i < n; ++i) {
    c[i] = std::floor(unit(rng) * 67108864) + 0.5;
    p[i] = i % 7 == 0 ? 1 : std::ldexp(unit(rng), -static_cast<int>(rng() % 40));
    q[i] = i % 5 == 0 ? 0 : i % 11 == 0 ? -p[i] : (2 * unit(rng) - 1) * p[i];
  }
  using Kernel = void (*)(double*, const double*, const double*, size_t, bool, double, double);
  const std::pair<VectorPath, Kernel> paths[] = {
      {VectorPath::kAvx, slope_batch::FollowSlopesAvx},
      {VectorPath::kAvx512, slope_batch::FollowSlopesAvx512},
      {BestVectorPath(), slope_batch::FollowSlopes}};
  for (const bool exact : {true, false}) {
    const double cells = exact ? 67108864 : 59049, inverse = 1 / cells;
    std::vector<double> want = c;
    slope_batch::FollowSlopesOf(want.data(), p.data(), q.data(), n, exact, cells, inverse);
    for (const auto& [path, kernel] : paths) {
      if (!Runs(path)) continue;
      for (size_t m : {n, size_t{1}, size_t{3}, size_t{9}, size_t{17}}) {
        std::vector<double> got(c.begin(), c.begin() + m);
        kernel(got.data(), p.data(), q.data(), m, exact, cells, inverse);
        for (size_t i = 0; i < m; ++i) {
          ASSERT_TRUE(SameBits(got[i], want[i])) << VectorPathName(path) << " i = " << i;
        }
      }
    }
  }
}

}  // namespace
}  // namespace sfc::math
