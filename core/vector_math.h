// Elementary functions with the same bits everywhere: SLEEF's deterministic
// ("cinz": no fused multiply-add) functions, so a sample's bytes depend on
// neither the C library's choice of code path (glibc picks FMA variants of
// sin, cos and pow on machines that have FMA) nor the vector width.
//
// Each batch function is dispatched once per process to the widest vector
// path the CPU offers (SSE2, AVX, AVX2, AVX-512F). Every path, and the scalar
// reference each batch function has, returns the same bits: SLEEF makes the
// cinz functions alike across instruction sets, and tests/vector_math_test.cc
// checks it bit for bit on the paths this machine has.
//
// Thread-safety: pure functions.
#ifndef SFCSAMPLER_CORE_VECTOR_MATH_H_
#define SFCSAMPLER_CORE_VECTOR_MATH_H_

#include <cstddef>
#include <string_view>

namespace sfc::math {

// The largest double below 1: where a coordinate of [0, 1) is clamped.
inline constexpr double kBelowOne = 1.0 - 0x1.0p-53;

// sin(pi x) and cos(pi x), within 3.5 ulp (SLEEF's u35 functions: three
// times as fast as its 0.506-ulp ones, and a sample's place is a few ulp of
// its cell at most), exact at multiples of 1/2 (the argument is reduced
// exactly, so no rounding of pi x creeps in).
struct SinCos {
  double sin, cos;
};
SinCos SinCosPi(double x);
// The same for x[0..n): s[i], c[i] equal SinCosPi(x[i]) bit for bit.
void SinCosPi(const double* x, size_t n, double* s, double* c);

// sin x and cos x within 1 ulp.
SinCos SinCosOf(double x);
// The same for x[0..n): s[i], c[i] equal SinCosOf(x[i]) bit for bit.
void SinCosOf(const double* x, size_t n, double* s, double* c);
// The cube root, within 3.5 ulp (SLEEF's u35 cbrt, three times as fast as
// Pow(x, 1/3)), odd in x. For the superellipsoid's default exponent 1/3.
double Cbrt(double x);
// Cbrt(x[i]) for x[0..n) into out[i], bit for bit.
void Cbrt(const double* x, size_t n, double* out);
// The C library's functions of the same names, within 1 ulp, with C's
// values at special arguments.
double Pow(double x, double y);
// Pow(x[i], y) for x[0..n) into out[i], bit for bit.
void Pow(const double* x, double y, size_t n, double* out);
double Exp(double x);
double Log(double x);
double Log2(double x);
double Log10(double x);
double Tan(double x);
double Asin(double x);
double Acos(double x);
double Atan(double x);
double Atan2(double y, double x);
double Sinh(double x);
double Cosh(double x);
double Tanh(double x);
double Asinh(double x);
double Acosh(double x);
double Atanh(double x);

// The vector paths, for tests and benchmarks, narrowest first. kAvx2 is kAvx
// and AVX2's 256-bit integer lanes and gathers: the loops that use them have
// builds of their own for it (core/curve_avx2.cc, core/tree_warp_avx2.cc,
// mesh/mesh_warp_avx2.cc), and kAvx runs the plain AVX builds (what an
// AVX-only CPU runs) on any CPU.
enum class VectorPath { kScalar, kSse2, kAvx, kAvx2, kAvx512 };
// Every path, narrowest first: the lists that tests and dispatch walk.
inline constexpr VectorPath kVectorPaths[] = {VectorPath::kScalar, VectorPath::kSse2,
                                              VectorPath::kAvx, VectorPath::kAvx2,
                                              VectorPath::kAvx512};
// The path the batch functions use: the widest this CPU runs, or another one
// it runs (scalar, sse2, avx, avx2, avx512f) named by the environment
// variable SFCSAMPLER_VECTOR_PATH, read once.
VectorPath BestVectorPath();
// "scalar", "sse2", "avx", "avx2" or "avx512f".
std::string_view VectorPathName(VectorPath path);
// Whether this CPU runs `path` (its instruction set, by CPUID).
bool Runs(VectorPath path);
// The path whose build a function with no build of its own for AVX2 runs
// (the elementary functions here, core/slope_batch.h): kAvx for kAvx2 (their
// floating-point loops have nothing to gain from AVX2), `path` otherwise.
// The one place that maps kAvx2 onto kAvx.
constexpr VectorPath WithoutAvx2(VectorPath path) {
  return path == VectorPath::kAvx2 ? VectorPath::kAvx : path;
}
// SinCosPi over a batch on one given path. REQUIRES: Runs(path).
void SinCosPiOn(VectorPath path, const double* x, size_t n, double* s, double* c);
// SinCosOf, Pow and Cbrt over a batch on one given path. REQUIRES: Runs(path).
void SinCosOfOn(VectorPath path, const double* x, size_t n, double* s, double* c);
void PowOn(VectorPath path, const double* x, double y, size_t n, double* out);
void CbrtOn(VectorPath path, const double* x, size_t n, double* out);

namespace vector_math_internal {
// The AVX and AVX-512F loops, each in a file built for its instruction set
// (vector_math_avx.cc, vector_math_avx512.cc); whole vectors only: n is a
// multiple of 4 resp. 8.
void SinCosPiAvx(const double* x, size_t n, double* s, double* c);
void SinCosPiAvx512(const double* x, size_t n, double* s, double* c);
void SinCosOfAvx(const double* x, size_t n, double* s, double* c);
void SinCosOfAvx512(const double* x, size_t n, double* s, double* c);
void PowAvx(const double* x, double y, size_t n, double* out);
void PowAvx512(const double* x, double y, size_t n, double* out);
void CbrtAvx(const double* x, size_t n, double* out);
void CbrtAvx512(const double* x, size_t n, double* out);
}  // namespace vector_math_internal

}  // namespace sfc::math

#endif  // SFCSAMPLER_CORE_VECTOR_MATH_H_
