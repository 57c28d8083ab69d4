#include "core/leaf_model.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <type_traits>

namespace sfc {
namespace {

using leaf_model_internal::BasisIntegrals;

template <typename T>
double Quadratic(const T* c, double x0, double x1, double y0, double y1) {
  double ix[3], iy[3];
  BasisIntegrals(x0, x1, ix);
  BasisIntegrals(y0, y1, iy);
  double sum = 0;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) sum += static_cast<double>(c[3 * i + j]) * ix[i] * iy[j];
  }
  return sum;
}

double Overlap(double a0, double a1, double b0, double b1) {
  return std::max(0.0, std::min(a1, b1) - std::max(a0, b0));
}

}  // namespace

LeafModel LeafModel::Uniform() {
  LeafModel m;
  std::fill(m.c, m.c + 9, 1.0f);
  m.warp[0] = m.warp[1] = kNoWarp;
  return m;
}

LeafModel LeafModel::FromQuadratic(const double values[9], const AxisWarp* warp) {
  double total = 0;
  bool ok = true;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      total += kGaussWeight[i] * kGaussWeight[j] * values[3 * i + j];
      ok = ok && std::isfinite(values[3 * i + j]) && values[3 * i + j] >= 0;
    }
  }
  if (!ok || !(total > 0) || !std::isfinite(total)) return Uniform();
  LeafModel m;
  for (int k = 0; k < 9; ++k) m.c[k] = static_cast<float>(values[k] / total);
  m.warp[0] = warp == nullptr ? kNoWarp : warp[0];
  m.warp[1] = warp == nullptr ? kNoWarp : warp[1];
  return m;
}

LeafModel LeafModel::FromPiecewise(const double masses[9], int grid) {
  const int n = grid * grid;
  double total = 0;
  bool ok = true;
  for (int k = 0; k < n; ++k) {
    total += masses[k];
    ok = ok && std::isfinite(masses[k]) && masses[k] >= 0;
  }
  LeafModel m = Uniform();
  if (!ok || !(total > 0) || !std::isfinite(total)) return m;
  // Density on a sub-square of area 1 / n: its share of the mass times n.
  for (int k = 0; k < n; ++k) m.c[k] = static_cast<float>(masses[k] / total * n);
  return m;
}

double ModelIntegral(const LeafModel& model, LeafModel::Kind kind, int grid, double x0, double x1,
                     double y0, double y1) {
  if (kind == LeafModel::Kind::kQuadratic) {
    return Quadratic(model.c, Unwarp(model.warp[0], x0), Unwarp(model.warp[0], x1),
                     Unwarp(model.warp[1], y0), Unwarp(model.warp[1], y1));
  }
  const double side = 1.0 / grid;
  double sum = 0;
  for (int i = 0; i < grid; ++i) {
    const double ox = Overlap(x0, x1, i * side, (i + 1) * side);
    if (ox == 0) continue;
    for (int j = 0; j < grid; ++j) {
      const double oy = Overlap(y0, y1, j * side, (j + 1) * side);
      if (oy > 0) sum += static_cast<double>(model.c[i * grid + j]) * ox * oy;
    }
  }
  return sum;
}

namespace {

// Two lanes of doubles (the baseline's SSE2 register): each lane does the
// scalar code's IEEE operations (no contraction: -ffp-contract=off).
typedef double Pair __attribute__((vector_size(16)));
Pair Load(const double* p) {
  Pair r;
  std::memcpy(&r, p, sizeof r);
  return r;
}
void Store(Pair x, double* p) { std::memcpy(p, &x, sizeof x); }

// BasisIntegrals(a, b, ...) into out[0][k], out[1][k], out[2][k]; with T =
// Pair, for two intervals at once (out[.][k], out[.][k + 1]); the same bits.
template <typename T>
void BasisIntegralsAt(T a, T b, double (*out)[kMaxGridCells], int k) {
  using leaf_model_internal::kBasisTable;
  const T d = b - a, mid = (a + b) / 2, d3 = d * d * d / 12;
  for (int i = 0; i < 3; ++i) {
    const double* c = kBasisTable.k[i];
    const T value = d * (c[0] + mid * (c[1] + mid * c[2])) + c[2] * d3;
    if constexpr (std::is_same_v<T, Pair>) {
      Store(value, &out[i][k]);
    } else {
      out[i][k] = value;
    }
  }
}

// The integrals along one axis over the cells [o + k step, o + (k + 1) step]
// into full[.][k] and over their lower halves into low[.][k], k < n.
void AxisIntegrals(double o, double step, int n, double (*full)[kMaxGridCells],
                   double (*low)[kMaxGridCells]) {
  int k = 0;
  for (; k + 2 <= n; k += 2) {
    const Pair a = {o + k * step, o + (k + 1) * step};
    BasisIntegralsAt(a, Pair{o + (k + 1) * step, o + (k + 2) * step}, full, k);
    BasisIntegralsAt(a, Pair{o + (k + 0.5) * step, o + (k + 1 + 0.5) * step}, low, k);
  }
  for (; k < n; ++k) {
    const double a = o + k * step;
    BasisIntegralsAt(a, o + (k + 1) * step, full, k);
    BasisIntegralsAt(a, o + (k + 0.5) * step, low, k);
  }
}

}  // namespace

void ComputeAxisFactors(double origin, double side, int n, AxisFactors* out) {
  out->n = n;
  AxisIntegrals(origin, side / n, n, out->full, out->low);
  if (n % 2 != 0) {  // QuadraticGridFactors takes rows in pairs: the last one's partner
    for (int b = 0; b < 3; ++b) out->full[b][n] = out->low[b][n] = 0;
  }
}

bool HasQuadraticGridFactors(const LeafModel& model, LeafModel::Kind kind) {
  return kind == LeafModel::Kind::kQuadratic && !(model.warp[0].power < 1) &&
         !(model.warp[1].power < 1);
}

void QuadraticGridFactors(const LeafModel& model, const AxisFactors& x, const AxisFactors& y,
                          GridFactors* out) {
  const int n = x.n;
  out->factors = 3;
  out->halves[0] = out->halves[1] = true;
  for (int b = 0; b < 3; ++b) {
    std::copy(x.full[b], x.full[b] + n, out->x[b]);
    std::copy(x.low[b], x.low[b] + n, out->x_low[b]);
  }
  for (int a = 0; a < 3; ++a) {
    const double c0 = model.c[3 * a], c1 = model.c[3 * a + 1], c2 = model.c[3 * a + 2];
    for (int j = 0; j < n; j += 2) {
      Pair sum = {0, 0}, sum_low = {0, 0};
      sum += c0 * Load(&y.full[0][j]), sum_low += c0 * Load(&y.low[0][j]);
      sum += c1 * Load(&y.full[1][j]), sum_low += c1 * Load(&y.low[1][j]);
      sum += c2 * Load(&y.full[2][j]), sum_low += c2 * Load(&y.low[2][j]);
      out->row[a][j] = sum[0], out->row_low[a][j] = sum_low[0];
      if (j + 1 < n) out->row[a][j + 1] = sum[1], out->row_low[a][j + 1] = sum_low[1];
    }
  }
}

void ComputeGridFactors(const LeafModel& model, LeafModel::Kind kind, int grid, double x0,
                        double y0, double side, int n, GridFactors* out) {
  const bool quadratic = kind == LeafModel::Kind::kQuadratic;
  if (HasQuadraticGridFactors(model, kind)) {
    AxisFactors x, y;
    ComputeAxisFactors(x0, side, n, &x);
    ComputeAxisFactors(y0, side, n, &y);
    QuadraticGridFactors(model, x, y, out);
    return;
  }
  const int factors = quadratic ? 3 : grid;
  out->factors = factors;
  const double step = side / n;
  // f[axis][b][k]: the integral of factor b along `axis` over its cell k;
  // low[axis][b][k] over the cell's lower half.
  double f[2][3][kMaxGridCells], low[2][3][kMaxGridCells];
  auto integrals = [&](double a, double b, double* out_factors) {
    if (quadratic) {
      leaf_model_internal::BasisIntegrals(a, b, out_factors);
    } else {
      const double piece = 1.0 / grid;
      for (int c = 0; c < grid; ++c) out_factors[c] = Overlap(a, b, c * piece, (c + 1) * piece);
    }
  };
  for (int axis = 0; axis < 2; ++axis) {
    const double origin = axis == 0 ? x0 : y0;
    double edge[kMaxGridCells + 1];
    for (int k = 0; k <= n; ++k) edge[k] = origin + k * step;
    // Descended in leaf coordinates: the cells' images in warped ones, and
    // no halves (the walk places uniformly in warped coordinates there).
    const bool unwarp = quadratic && model.warp[axis].power < 1;
    if (unwarp) {
      for (int k = 0; k <= n; ++k) edge[k] = Unwarp(model.warp[axis], edge[k]);
    }
    out->halves[axis] = !unwarp;
    for (int k = 0; k < n; ++k) {
      double values[3];
      integrals(edge[k], edge[k + 1], values);
      for (int b = 0; b < factors; ++b) f[axis][b][k] = values[b];
      if (unwarp) continue;
      integrals(edge[k], origin + (k + 0.5) * step, values);
      for (int b = 0; b < factors; ++b) low[axis][b][k] = values[b];
    }
  }
  for (int a = 0; a < factors; ++a) {
    for (int i = 0; i < n; ++i) out->x[a][i] = f[0][a][i];
    if (out->halves[0]) {
      for (int i = 0; i < n; ++i) out->x_low[a][i] = low[0][a][i];
    }
    for (int j = 0; j < n; ++j) {
      double sum = 0, sum_low = 0;
      for (int b = 0; b < factors; ++b) {
        const double c = model.c[a * factors + b];
        sum += c * f[1][b][j];
        if (out->halves[1]) sum_low += c * low[1][b][j];
      }
      out->row[a][j] = sum;
      out->row_low[a][j] = sum_low;
    }
  }
}

double QuadraticIntegral(const double values[9], double x0, double x1, double y0, double y1,
                         const AxisWarp* warp) {
  if (warp != nullptr) {
    x0 = Unwarp(warp[0], x0), x1 = Unwarp(warp[0], x1);
    y0 = Unwarp(warp[1], y0), y1 = Unwarp(warp[1], y1);
  }
  return Quadratic(values, x0, x1, y0, y1);
}

}  // namespace sfc
