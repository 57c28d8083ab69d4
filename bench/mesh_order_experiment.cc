// Issue 19's mesh gap, measured: why does the 81 920-triangle icosphere
// score a flatter spherical-triangle slope than the built-in sphere? This
// emulates the mesh sampler's outer loop (jittered q_k along the cumulative
// flat area of the triangles in curve order, projected to the unit sphere)
// with the triangles in different orders and two placements inside a
// triangle, so the order and the placement can be judged apart:
//   hilbert3d    the mesh's order (3D Hilbert keys of the centroids, 21 bits,
//                as mesh/mesh_curve_tree.cc)
//   sphere-uv    2D Hilbert order of the centroids' sphere parameters
//                (theta / pi, phi / 2 pi), as the built-in sphere's curve
//   random       a random order (the control: i.i.d.-like, ~ -0.5)
// Placement: "curve" = the sample's fraction of its triangle's mass followed
// down the triangle's Sierpinski curve, as mesh/mesh_curve_tree.h describes
// it (entry and exit at the ends of the longest edge, the exit nearer the
// next triangle's centroid; (E, X, A) splits at M = (E + X) / 2 into
// (E, A, M) then (A, X, M)), 40 levels; "random" = uniform in the triangle,
// independent of the jitter; "centroid" = the triangle's centroid (snapping).
// Prints the mean +- SE over seeds of the slope for N = 64..6144 and D at
// 6144 (128 random spherical triangles per seed, as `sfcsampler eval`).
// Usage: mesh_order_experiment [subdivisions=6] [seeds=3]
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "core/hilbert3d.h"
#include "evaluation/discrepancy.h"
#include "evaluation/quality.h"
#include "mesh/icosphere.h"

namespace {

constexpr double kPi = 3.14159265358979323846;

uint64_t Hilbert2(uint32_t n, uint32_t x, uint32_t y) {  // n a power of 2
  uint64_t d = 0;
  for (uint32_t s = n / 2; s > 0; s /= 2) {
    const uint32_t rx = (x & s) > 0, ry = (y & s) > 0;
    d += static_cast<uint64_t>(s) * s * ((3 * rx) ^ ry);
    if (ry == 0) {
      if (rx == 1) x = n - 1 - x, y = n - 1 - y;
      std::swap(x, y);
    }
  }
  return d;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace sfc;
  const int subdivisions = argc > 1 ? std::stoi(argv[1]) : 6;
  const int seeds = argc > 2 ? std::stoi(argv[2]) : 3;
  const TriangleMesh mesh = MakeIcosphere(subdivisions);
  const size_t t_count = mesh.triangles.size();
  std::vector<Vec3> c(t_count);
  std::vector<double> area(t_count);
  Vec3 lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
  for (size_t t = 0; t < t_count; ++t) {
    const auto& f = mesh.triangles[t];
    c[t] = (mesh.positions[f[0]] + mesh.positions[f[1]] + mesh.positions[f[2]]) * (1.0 / 3);
    area[t] = 0.5 * Norm(mesh.FaceCross(t));
    lo = {std::min(lo.x, c[t].x), std::min(lo.y, c[t].y), std::min(lo.z, c[t].z)};
    hi = {std::max(hi.x, c[t].x), std::max(hi.y, c[t].y), std::max(hi.z, c[t].z)};
  }
  std::vector<std::pair<std::string, std::vector<uint32_t>>> orders;
  auto sorted_by = [&](auto key) {
    std::vector<std::pair<uint64_t, uint32_t>> k(t_count);
    for (size_t t = 0; t < t_count; ++t) k[t] = {key(t), static_cast<uint32_t>(t)};
    std::sort(k.begin(), k.end());
    std::vector<uint32_t> o(t_count);
    for (size_t i = 0; i < t_count; ++i) o[i] = k[i].second;
    return o;
  };
  {
    const double cells = std::ldexp(1.0, 21);
    const double extent = std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
    const double scale = (cells - 1) / extent;
    auto q = [&](double v, double l) {
      return static_cast<uint32_t>(std::clamp((v - l) * scale, 0.0, cells - 1));
    };
    orders.push_back({"hilbert3d", sorted_by([&](size_t t) {
                        return HilbertKey3(q(c[t].x, lo.x), q(c[t].y, lo.y), q(c[t].z, lo.z), 21);
                      })});
  }
  orders.push_back({"sphere-uv", sorted_by([&](size_t t) {
                      const Vec3 p = c[t] * (1 / Norm(c[t]));
                      const double u = std::acos(std::clamp(p.z, -1.0, 1.0)) / kPi;
                      double v = std::atan2(p.y, p.x) / (2 * kPi);
                      if (v < 0) v += 1;
                      const uint32_t n = 1u << 16;
                      return Hilbert2(n, std::min(n - 1, static_cast<uint32_t>(u * n)),
                                      std::min(n - 1, static_cast<uint32_t>(v * n)));
                    })});
  {
    std::vector<uint32_t> o(t_count);
    for (size_t t = 0; t < t_count; ++t) o[t] = static_cast<uint32_t>(t);
    std::shuffle(o.begin(), o.end(), std::mt19937_64(99));
    orders.push_back({"random", o});
  }
  std::vector<uint64_t> sizes;
  for (int l = 6; l <= 12; ++l) {
    for (uint64_t n : {uint64_t{1} << l, (uint64_t{3} << l) / 2}) {
      if (n <= 6144) sizes.push_back(n);
    }
  }
  std::printf(
      "icosphere of %zu triangles; N = %llu..%llu; %d seeds; 128 spherical triangles per seed\n\n",
      t_count, static_cast<unsigned long long>(sizes.front()),
      static_cast<unsigned long long>(sizes.back()), seeds);
  // Why an order scores as it does: how compact a run of the curve holding
  // 1/N of the area is (area-weighted RMS distance of its triangles'
  // centroids from their mean, over sqrt(4 pi / N)), and how often the curve
  // jumps (consecutive centroids further apart than 3 mean edge lengths).
  const double edge = std::sqrt(4 * 4 * kPi / (std::sqrt(3.0) * t_count));
  std::printf(
      "| order | RMS radius of a 1/N run, N = 1024 | N = 6144 | jumps > 3 edges per 1000 steps "
      "|\n|---|---:|---:|---:|\n");
  for (const auto& [name, order] : orders) {
    double spread[2];
    int idx = 0;
    for (uint64_t n : {uint64_t{1024}, uint64_t{6144}}) {
      double sum = 0;
      const size_t per = t_count / n;
      for (size_t r = 0; r + per <= t_count; r += per) {
        Vec3 mean{0, 0, 0};
        double w = 0;
        for (size_t i = r; i < r + per; ++i)
          mean = mean + c[order[i]] * area[order[i]], w += area[order[i]];
        mean = mean * (1 / w);
        double ss = 0;
        for (size_t i = r; i < r + per; ++i)
          ss += area[order[i]] * Dot(c[order[i]] - mean, c[order[i]] - mean);
        sum += std::sqrt(ss / w);
      }
      spread[idx++] = sum / (t_count / per) / std::sqrt(4 * kPi / n);
    }
    size_t jumps = 0;
    for (size_t i = 0; i + 1 < t_count; ++i)
      jumps += Norm(c[order[i + 1]] - c[order[i]]) > 3 * edge;
    std::printf("| %s | %.3f | %.3f | %.2f |\n", name.c_str(), spread[0], spread[1],
                1000.0 * jumps / (t_count - 1));
  }
  std::printf(
      "\n| order | placement | slope (mean +- SE) | D at N = 6144 |\n|---|---|---:|---:|\n");
  for (const auto& [name, order] : orders) {
    std::vector<double> cum(t_count + 1, 0);
    for (size_t i = 0; i < t_count; ++i) cum[i + 1] = cum[i] + area[order[i]];
    for (const char* placement : {"curve", "random", "centroid"}) {
      std::vector<double> slopes, last;
      for (int s = 1; s <= seeds; ++s) {
        std::vector<double> ns, ds;
        for (uint64_t n : sizes) {
          std::mt19937_64 rng(s * 7919 + n);
          std::uniform_real_distribution<double> uni(0, 1);
          std::vector<Vec3> pts(n);
          for (uint64_t k = 0; k < n; ++k) {
            const double m = (k + uni(rng)) / n * cum.back();
            const size_t i = std::min(
                t_count - 1,
                static_cast<size_t>(std::upper_bound(cum.begin(), cum.end(), m) - cum.begin()) - 1);
            const auto& f = mesh.triangles[order[i]];
            Vec3 p = c[order[i]];
            if (std::string(placement) == "curve") {
              // Longest edge (P, Q), apex R; exit = the end nearer the next centroid.
              Vec3 v3[3] = {mesh.positions[f[0]], mesh.positions[f[1]], mesh.positions[f[2]]};
              int longest = 0;
              double best = -1;
              for (int e = 0; e < 3; ++e) {
                const double len = Norm(v3[(e + 1) % 3] - v3[e]);
                if (len > best) best = len, longest = e;
              }
              Vec3 entry = v3[longest], exit = v3[(longest + 1) % 3], apex = v3[(longest + 2) % 3];
              const Vec3 next = c[order[std::min(t_count - 1, i + 1)]];
              if (Norm(entry - next) < Norm(exit - next)) std::swap(entry, exit);
              double frac = (m - cum[i]) / (cum[i + 1] - cum[i]);
              for (int level = 0; level < 40; ++level) {
                const Vec3 mid = (entry + exit) * 0.5;
                if (frac < 0.5) {
                  exit = apex, apex = mid, frac *= 2;  // (E, A, M)
                } else {
                  entry = apex, apex = mid, frac = 2 * frac - 1;  // (A, X, M)
                }
              }
              p = (entry + exit + apex) * (1.0 / 3);
            } else if (std::string(placement) == "random") {
              double a = uni(rng), b = uni(rng);
              if (a + b > 1) a = 1 - a, b = 1 - b;
              p = mesh.positions[f[0]] + (mesh.positions[f[1]] - mesh.positions[f[0]]) * a +
                  (mesh.positions[f[2]] - mesh.positions[f[0]]) * b;
            }
            pts[k] = p * (1 / Norm(p));
          }
          ns.push_back(static_cast<double>(n));
          ds.push_back(SphericalTriangleDiscrepancy(pts, 128, s));
        }
        slopes.push_back(LogLogSlope(ns, ds));
        last.push_back(ds.back());
      }
      double m, se, dm, dse;
      MeanAndStandardError(slopes, &m, &se);
      MeanAndStandardError(last, &dm, &dse);
      std::printf("| %s | %s | %.3f +- %.3f | %.2e +- %.1e |\n", name.c_str(), placement, m, se, dm,
                  dse);
      std::fflush(stdout);
    }
  }
  return 0;
}
