#include "evaluation/reference_sets.h"

#include <algorithm>
#include <cmath>

#include "base/counter_hash.h"

namespace sfc {
namespace {

constexpr double kPi = 3.14159265358979323846;

Vec3 FromZPhi(double z, double phi) {
  const double s = std::sqrt(std::max(0.0, 1 - z * z));
  return {s * std::cos(phi), s * std::sin(phi), z};
}

}  // namespace

double RadicalInverse2(uint64_t k) {
  uint64_t r = 0;
  for (int i = 0; i < 64; ++i, k >>= 1) r = (r << 1) | (k & 1);
  return static_cast<double>(r >> 11) * 0x1.0p-53;
}

std::vector<Point2> RandomSquare(uint64_t n, uint64_t seed) {
  std::vector<Point2> p(n);
  for (uint64_t i = 0; i < n; ++i)
    p[i] = {CounterUniform(seed, 21, i), CounterUniform(seed, 22, i)};
  return p;
}

std::vector<Point2> JitteredSquare(uint64_t n, uint64_t seed) {
  std::vector<Point2> p;
  p.reserve(n);
  const uint64_t rows =
      std::max<uint64_t>(1, static_cast<uint64_t>(std::sqrt(static_cast<double>(n))));
  uint64_t k = 0;
  double y0 = 0;
  for (uint64_t r = 0; r < rows; ++r) {
    const uint64_t cells = n / rows + (r < n % rows ? 1 : 0);
    const double height = static_cast<double>(cells) / n;  // equal-area strata
    for (uint64_t c = 0; c < cells; ++c, ++k) {
      p.push_back(
          {(c + CounterUniform(seed, 23, k)) / cells, y0 + height * CounterUniform(seed, 24, k)});
    }
    y0 += height;
  }
  return p;
}

std::vector<Point2> SobolSquare(uint64_t n) {
  uint32_t v[32];
  v[0] = 1u << 31;
  for (int k = 1; k < 32; ++k) v[k] = v[k - 1] ^ (v[k - 1] >> 1);
  std::vector<Point2> p(n);
  for (uint64_t i = 0; i < n; ++i) {
    uint32_t y = 0;
    uint64_t bits = i;
    for (int k = 0; bits; ++k, bits >>= 1) {
      if (bits & 1) y ^= v[k];
    }
    p[i] = {RadicalInverse2(i), y * 0x1.0p-32};
  }
  return p;
}

std::vector<Point2> HaltonSquare(uint64_t n) {
  std::vector<Point2> p(n);
  for (uint64_t i = 0; i < n; ++i) {
    double y = 0, f = 1.0 / 3;
    for (uint64_t k = i; k; k /= 3, f /= 3) y += (k % 3) * f;
    p[i] = {RadicalInverse2(i), y};
  }
  return p;
}

std::vector<Point2> HammersleySquare(uint64_t n) {
  std::vector<Point2> p(n);
  for (uint64_t i = 0; i < n; ++i) p[i] = {static_cast<double>(i) / n, RadicalInverse2(i)};
  return p;
}

std::vector<Vec3> RandomSphere(uint64_t n, uint64_t seed) {
  std::vector<Vec3> p(n);
  for (uint64_t i = 0; i < n; ++i) {
    p[i] = FromZPhi(1 - 2 * CounterUniform(seed, 25, i), 2 * kPi * CounterUniform(seed, 26, i));
  }
  return p;
}

std::vector<Vec3> HammersleySphere(uint64_t n) {
  std::vector<Vec3> p(n);
  for (uint64_t k = 0; k < n; ++k)
    p[k] = FromZPhi(2 * RadicalInverse2(k) - 1, 2 * kPi * (k + 0.5) / n);
  return p;
}

std::vector<Vec3> FibonacciSphere(uint64_t n) {
  const double golden = (1 + std::sqrt(5.0)) / 2;
  std::vector<Vec3> p(n);
  for (uint64_t k = 0; k < n; ++k) {
    p[k] = FromZPhi(1 - (2.0 * k + 1) / n, 2 * kPi * std::fmod(k / golden, 1.0));
  }
  return p;
}

}  // namespace sfc
