#include "mesh/triangle_mesh.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "absl/strings/str_format.h"
#include "base/status_macros.h"
#include "core/area_estimator.h"

namespace sfc {

bool IsDegenerateTriangle(const TriangleMesh& mesh, size_t t) {
  return IsDegenerateTriangle(mesh, t, Norm(mesh.FaceCross(t)));
}

bool IsDegenerateTriangle(const TriangleMesh& mesh, size_t t, double cross_norm) {
  const auto& f = mesh.triangles[t];
  if (f[0] == f[1] || f[1] == f[2] || f[0] == f[2]) return true;
  const Vec3& a = mesh.positions[f[0]];
  const Vec3& b = mesh.positions[f[1]];
  const Vec3& c = mesh.positions[f[2]];
  const double longest2 = std::max({Dot(b - a, b - a), Dot(c - b, c - b), Dot(a - c, a - c)});
  return !(cross_norm > 1e-12 * longest2);
}

void ForEachEdge(const TriangleMesh& mesh,
                 const std::function<void(uint32_t a, uint32_t b, uint32_t n)>& f) {
  const size_t nv = mesh.positions.size();
  std::vector<uint32_t> start(nv + 1, 0);
  std::vector<uint8_t> degenerate(mesh.triangles.size());  // tested once, used twice
  for (size_t t = 0; t < mesh.triangles.size(); ++t) degenerate[t] = IsDegenerateTriangle(mesh, t);
  auto for_each_half = [&](auto&& visit) {
    for (size_t t = 0; t < mesh.triangles.size(); ++t) {
      if (degenerate[t]) continue;
      const auto& tri = mesh.triangles[t];
      for (int c = 0; c < 3; ++c) {
        const uint32_t a = tri[c], b = tri[(c + 1) % 3];
        visit(std::min(a, b), std::max(a, b));
      }
    }
  };
  for_each_half([&](uint32_t a, uint32_t) { ++start[a + 1]; });
  for (size_t i = 0; i < nv; ++i) start[i + 1] += start[i];
  std::vector<uint32_t> fill(start.begin(), start.end() - 1), other(start[nv]);
  for_each_half([&](uint32_t a, uint32_t b) { other[fill[a]++] = b; });
  for (size_t a = 0; a < nv; ++a) {
    const auto begin = other.begin() + start[a], end = other.begin() + start[a + 1];
    std::sort(begin, end);  // a handful of neighbours
    for (auto i = begin; i != end;) {
      auto j = i;
      while (j != end && *j == *i) ++j;
      f(static_cast<uint32_t>(a), *i, static_cast<uint32_t>(j - i));
      i = j;
    }
  }
}

absl::Status FinalizeMesh(TriangleMesh* mesh) {
  const std::string& name = mesh->name;
  const size_t nv = mesh->positions.size();
  MeshStats& stats = mesh->stats;
  stats.vertices = nv;
  if (mesh->triangles.empty()) {
    return absl::InvalidArgumentError(
        absl::StrFormat("mesh '%s' has no triangles: give a file with at least one face", name));
  }
  for (size_t i = 0; i < nv; ++i) {
    if (!IsFinite(mesh->positions[i])) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "mesh '%s': vertex %d has a coordinate that is not a finite number (NaN or infinity)",
          name, i));
    }
  }
  // The size is that of the vertices the triangles use: a stray vertex that
  // no triangle uses is never sampled, so it neither widens the box nor makes
  // a mesh too large.
  Vec3 lo{INFINITY, INFINITY, INFINITY}, hi{-INFINITY, -INFINITY, -INFINITY};
  for (size_t t = 0; t < mesh->triangles.size(); ++t) {
    const auto& f = mesh->triangles[t];
    for (int c = 0; c < 3; ++c) {
      if (f[c] >= nv) {
        return absl::InvalidArgumentError(absl::StrFormat(
            "mesh '%s': triangle %d uses vertex %d but the mesh has %d vertices (a truncated "
            "file?)",
            name, t, f[c], nv));
      }
      const Vec3& p = mesh->positions[f[c]];
      lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
      hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
    }
  }
  RETURN_IF_ERROR(CheckSize(absl::StrFormat("mesh '%s'", name), Diagonal(lo, hi)));
  stats.lo = lo, stats.hi = hi;
  if (!mesh->normals.empty()) {
    if (mesh->normals.size() != nv) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "mesh '%s' has %d normals for %d vertices", name, mesh->normals.size(), nv));
    }
    for (Vec3& n : mesh->normals) {
      const double len = Norm(n);
      // A zero or non-finite normal makes the column meaningless: use face normals.
      if (!(len > 0) || !std::isfinite(len)) {
        mesh->normals.clear();
        break;
      }
      n = n * (1.0 / len);
    }
  }
  if (!mesh->weights.empty()) {
    if (mesh->weights.size() != nv) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "mesh '%s' has %d weights for %d vertices", name, mesh->weights.size(), nv));
    }
    for (size_t i = 0; i < nv; ++i) {
      if (!std::isfinite(mesh->weights[i]) || mesh->weights[i] < 0) {
        return absl::InvalidArgumentError(absl::StrFormat(
            "mesh '%s': vertex %d has weight %g; weights must be finite and >= 0", name, i,
            mesh->weights[i]));
      }
    }
  }
  stats.degenerate_triangles = 0;
  stats.area = 0;
  for (size_t t = 0; t < mesh->triangles.size(); ++t) {
    const double cross_norm = Norm(mesh->FaceCross(t));
    if (IsDegenerateTriangle(*mesh, t, cross_norm)) {
      ++stats.degenerate_triangles;
      continue;
    }
    stats.area += 0.5 * cross_norm;
  }
  if (stats.degenerate_triangles == mesh->triangles.size()) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "mesh '%s': all %d triangles are degenerate (no area): nothing to sample", name,
        mesh->triangles.size()));
  }
  return absl::OkStatus();
}

void CountEdges(TriangleMesh* mesh) {
  MeshStats& stats = mesh->stats;
  stats.non_manifold_edges = stats.boundary_edges = 0;
  ForEachEdge(*mesh, [&stats](uint32_t, uint32_t, uint32_t n) {
    if (n == 1) ++stats.boundary_edges;
    if (n > 2) ++stats.non_manifold_edges;
  });
}

}  // namespace sfc
