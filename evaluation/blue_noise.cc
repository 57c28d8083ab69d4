#include "evaluation/blue_noise.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <random>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "evaluation/reference_sets.h"

namespace sfc {
namespace {

constexpr double kPi = 3.14159265358979323846;

double PlaneSpacing(size_t n) { return std::sqrt(2 / (std::sqrt(3.0) * n)); }
double SphereSpacing(size_t n) { return std::sqrt(8 * kPi / (std::sqrt(3.0) * n)); }

uint32_t ReverseBits(uint32_t x) {
  x = ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
  x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
  x = ((x >> 4) & 0x0F0F0F0Fu) | ((x & 0x0F0F0F0Fu) << 4);
  x = ((x >> 8) & 0x00FF00FFu) | ((x & 0x00FF00FFu) << 8);
  return (x >> 16) | (x << 16);
}

// Burley 2020, "Practical Hash-based Owen Scrambling", Listing 2 (the
// Laine-Karras permutation with better constants), on the reversed bits.
uint32_t OwenScramble(uint32_t x, uint32_t seed) {
  x = ReverseBits(x);
  x ^= x * 0x3d20adeau;
  x += seed;
  x *= (seed >> 16) | 1;
  x ^= x * 0x05526c56u;
  x ^= x * 0x53a22864u;
  return ReverseBits(x);
}

template <typename P, typename Dist>
NearestNeighbour Stats(const std::vector<P>& pts, double spacing, Dist dist) {
  NearestNeighbour r;
  const size_t n = pts.size();
  if (n < 2) return r;
  double lo = INFINITY, sum = 0;
  for (size_t i = 0; i < n; ++i) {
    double best = INFINITY;
    for (size_t j = 0; j < n; ++j) {
      if (j != i) best = std::min(best, dist(pts[i], pts[j]));
    }
    lo = std::min(lo, best);
    sum += best;
  }
  r.min = lo / spacing;
  r.mean = sum / n / spacing;
  return r;
}

}  // namespace

NearestNeighbour PlaneNearestNeighbour(const std::vector<Point2>& points) {
  return Stats(points, PlaneSpacing(points.size()),
               [](const Point2& a, const Point2& b) { return std::hypot(a.x - b.x, a.y - b.y); });
}

NearestNeighbour SphereNearestNeighbour(const std::vector<Vec3>& points) {
  return Stats(points, SphereSpacing(points.size()),
               [](const Vec3& a, const Vec3& b) { return Norm(a - b); });
}

std::vector<Point2> ScrambledSobolSquare(uint64_t n, uint64_t seed) {
  std::vector<Point2> p = SobolSquare(n);
  std::mt19937_64 rng(seed);
  const uint32_t sx = static_cast<uint32_t>(rng()), sy = static_cast<uint32_t>(rng());
  for (Point2& q : p) {
    const uint32_t x = static_cast<uint32_t>(q.x * 0x1.0p32),
                   y = static_cast<uint32_t>(q.y * 0x1.0p32);
    // Bits below 2^-32 are random too (the scramble's last level).
    q.x = (OwenScramble(x, sx) + 0.5) * 0x1.0p-32;
    q.y = (OwenScramble(y, sy) + 0.5) * 0x1.0p-32;
  }
  return p;
}

std::vector<Vec3> SquareToSphere(const std::vector<Point2>& points) {
  std::vector<Vec3> out;
  for (const Point2& p : points) {
    const double z = 1 - 2 * p.x, phi = 2 * kPi * p.y, s = std::sqrt(std::max(0.0, 1 - z * z));
    out.push_back({s * std::cos(phi), s * std::sin(phi), z});
  }
  return out;
}

std::vector<Point2> DartThrowingSquare(uint64_t n, double radius, uint64_t seed) {
  const double r = radius * PlaneSpacing(n);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uni(0, 1);
  const int g = std::max(1, static_cast<int>(1 / r));  // cells of side >= r
  std::vector<std::vector<int>> grid(static_cast<size_t>(g) * g);
  std::vector<Point2> out;
  for (uint64_t tries = 0; out.size() < n && tries < 1000 * n; ++tries) {
    const Point2 c{uni(rng), uni(rng)};
    const int ci = std::min(g - 1, static_cast<int>(c.x * g)),
              cj = std::min(g - 1, static_cast<int>(c.y * g));
    bool ok = true;
    for (int i = std::max(0, ci - 1); ok && i <= std::min(g - 1, ci + 1); ++i) {
      for (int j = std::max(0, cj - 1); ok && j <= std::min(g - 1, cj + 1); ++j) {
        for (int k : grid[i * g + j]) ok = ok && std::hypot(out[k].x - c.x, out[k].y - c.y) >= r;
      }
    }
    if (!ok) continue;
    grid[ci * g + cj].push_back(static_cast<int>(out.size()));
    out.push_back(c);
  }
  return out;
}

std::vector<Vec3> DartThrowingSphere(uint64_t n, double radius, uint64_t seed) {
  const double r = radius * SphereSpacing(n);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uni(0, 1);
  // Cells of a cube grid over [-1,1]^3 of side >= r.
  const int g = std::max(1, static_cast<int>(2 / r));
  auto cell = [&](double x) { return std::clamp(static_cast<int>((x + 1) / 2 * g), 0, g - 1); };
  std::vector<std::vector<int>> grid(static_cast<size_t>(g) * g * g);
  std::vector<Vec3> out;
  for (uint64_t tries = 0; out.size() < n && tries < 1000 * n; ++tries) {
    const double z = 1 - 2 * uni(rng), phi = 2 * kPi * uni(rng),
                 s = std::sqrt(std::max(0.0, 1 - z * z));
    const Vec3 c{s * std::cos(phi), s * std::sin(phi), z};
    const int ci = cell(c.x), cj = cell(c.y), ck = cell(c.z);
    bool ok = true;
    for (int i = std::max(0, ci - 1); ok && i <= std::min(g - 1, ci + 1); ++i) {
      for (int j = std::max(0, cj - 1); ok && j <= std::min(g - 1, cj + 1); ++j) {
        for (int k = std::max(0, ck - 1); ok && k <= std::min(g - 1, ck + 1); ++k) {
          for (int p : grid[(static_cast<size_t>(i) * g + j) * g + k])
            ok = ok && Norm(out[p] - c) >= r;
        }
      }
    }
    if (!ok) continue;
    grid[(static_cast<size_t>(ci) * g + cj) * g + ck].push_back(static_cast<int>(out.size()));
    out.push_back(c);
  }
  return out;
}

std::vector<double> RadialPowerSpectrum(const std::vector<Point2>& points, int max_frequency) {
  const int m = max_frequency;
  std::vector<double> sum(m + 1, 0.0);
  std::vector<int> count(m + 1, 0);
  // Half the wave vectors (P(k) = P(-k)): ky > 0, or ky = 0 and kx > 0.
  const size_t width = 2 * static_cast<size_t>(m) + 1;
  std::vector<std::complex<double>> acc(width * (m + 1));
  std::vector<std::complex<double>> ex(width);
  for (const Point2& p : points) {
    const std::complex<double> wx = std::polar(1.0, -2 * kPi * p.x);
    const std::complex<double> wy = std::polar(1.0, -2 * kPi * p.y);
    // ex[kx + m] = wx^kx for kx in [-m, m].
    ex[m] = 1;
    for (int k = 1; k <= m; ++k) {
      ex[m + k] = ex[m + k - 1] * wx;
      ex[m - k] = std::conj(ex[m + k]);
    }
    std::complex<double> ey = 1;
    for (int ky = 0; ky <= m; ++ky) {
      std::complex<double>* row = &acc[ky * width];
      for (size_t kx = 0; kx < width; ++kx) row[kx] += ex[kx] * ey;
      ey *= wy;
    }
  }
  for (int ky = 0; ky <= m; ++ky) {
    for (int kx = -m; kx <= m; ++kx) {
      if (ky == 0 && kx <= 0) continue;
      const int f = static_cast<int>(std::lround(std::sqrt(double(kx) * kx + double(ky) * ky)));
      if (f < 1 || f > m) continue;
      sum[f] += std::norm(acc[ky * width + kx + m]) / static_cast<double>(points.size());
      ++count[f];
    }
  }
  std::vector<double> out(m);
  for (int f = 1; f <= m; ++f) out[f - 1] = count[f] ? sum[f] / count[f] : 0;
  return out;
}

std::string PointsAndSpectrumSvg(const std::string& title, const std::vector<Point2>& points,
                                 const std::vector<double>& spectrum) {
  const double side = 400, gap = 40, plot_w = 400, plot_h = 400;
  std::string svg = absl::StrFormat(
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%d\" height=\"%d\">\n"
      "<rect width=\"100%%\" height=\"100%%\" fill=\"white\"/>\n"
      "<text x=\"10\" y=\"20\" font-family=\"sans-serif\" font-size=\"14\">%s</text>\n"
      "<g transform=\"translate(10,30)\"><rect width=\"%g\" height=\"%g\" fill=\"none\" "
      "stroke=\"black\"/>\n",
      static_cast<int>(side + gap + plot_w + 20), static_cast<int>(plot_h + 60), title, side, side);
  for (const Point2& p : points) {
    absl::StrAppendFormat(&svg, "<circle cx=\"%.1f\" cy=\"%.1f\" r=\"1.2\"/>\n", p.x * side,
                          (1 - p.y) * side);
  }
  absl::StrAppend(&svg, "</g>\n");
  // The spectrum: f / sqrt(N) on x (0 .. max), P on y (0 .. 4).
  const double root_n = std::sqrt(static_cast<double>(points.size()));
  const double x_max = spectrum.size() / root_n, y_max = 4;
  absl::StrAppendFormat(&svg,
                        "<g transform=\"translate(%g,30)\"><rect width=\"%g\" height=\"%g\" "
                        "fill=\"none\" stroke=\"black\"/>\n",
                        10 + side + gap, plot_w, plot_h);
  absl::StrAppendFormat(&svg,
                        "<line x1=\"0\" y1=\"%.1f\" x2=\"%g\" y2=\"%.1f\" stroke=\"gray\" "
                        "stroke-dasharray=\"4 4\"/>\n",
                        plot_h * (1 - 1 / y_max), plot_w, plot_h * (1 - 1 / y_max));
  absl::StrAppend(&svg, "<polyline fill=\"none\" stroke=\"blue\" points=\"");
  for (size_t f = 1; f <= spectrum.size(); ++f) {
    absl::StrAppendFormat(&svg, "%.1f,%.1f ", plot_w * (f / root_n) / x_max,
                          plot_h * (1 - std::min(spectrum[f - 1], y_max) / y_max));
  }
  absl::StrAppendFormat(
      &svg,
      "\"/>\n<text x=\"5\" y=\"15\" font-family=\"sans-serif\" font-size=\"12\">P(f), "
      "0 .. %g; f / sqrt(N), 0 .. %.2f (dashed: P = 1)</text>\n</g>\n</svg>\n",
      y_max, x_max);
  return svg;
}

}  // namespace sfc
