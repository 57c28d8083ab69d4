#!/usr/bin/python3
"""Would charts give a mesh quasi-Monte Carlo rates? A study for issue 36, outside the sampler.

The mesh warp (mesh/mesh_warp.h) maps the square onto the mesh through the curve's mass, so a
net's box holds about N / leaves points under one smooth map (docs/QUALITY.md, "Why the mesh
misses"). The way out named there is a parameterisation: charts, each mapped from the square by
one continuous map. This script builds that map in numpy and measures what it would give:
  * charts: triangles grown breadth-first from a seed while their normals stay within --cone
    degrees of the seed's, each projected orthographically on the plane normal to its
    area-weighted mean normal (no fold: every projected triangle keeps its orientation);
  * the square to the charts: the mesh warp's dyadic halving, the first coordinate at even
    depths, over the charts' masses in order, down to the first node inside one chart, so that
    every line between charts is a line of the net's elementary intervals;
  * inside a chart, the node's share of the chart's mass picks x by the exact marginal of area
    over the plane (piecewise quadratic between the vertices' x), the other coordinate y by the
    exact conditional at that x (piecewise linear), then the triangle and its barycentric point.
Points: scipy's scrambled Sobol (LMS + digital shift); integrand and exact mean: the icosphere of
bench/sobol_integration.py and its g over the flat triangles (edge-midpoint rule, exact). The
sampler's own `jittered` and `sobol` run through the CLI in the same run, same seeds.

Usage: /usr/bin/python3 bench/sobol_mesh_charts.py [--cli build/client/sfcsampler]
           [--cone 70] [--exponents 13,15,16,17] [--seeds 6]
"""
import argparse
import collections
import math
import os
import subprocess
import sys
import tempfile

import numpy as np
from scipy.stats import qmc

from compare_samplers import icosphere
from sobol_integration import g_quadratic, icosphere_obj


def grow_charts(verts, faces, cone_degrees):
    """Lists of triangle indices, grown breadth-first across shared edges."""
    a, b, c = verts[faces[:, 0]], verts[faces[:, 1]], verts[faces[:, 2]]
    normal = np.cross(b - a, c - a)
    area = np.linalg.norm(normal, axis=1) / 2
    normal /= (2 * area)[:, None]
    by_edge = collections.defaultdict(list)
    for t, face in enumerate(faces):
        for i in range(3):
            by_edge[tuple(sorted((face[i], face[(i + 1) % 3])))].append(t)
    neighbours = [[] for _ in faces]
    for ts in by_edge.values():
        for s in ts:
            neighbours[s] += [t for t in ts if t != s]
    chart_of = -np.ones(len(faces), int)
    charts, limit = [], math.cos(math.radians(cone_degrees))
    for seed in range(len(faces)):
        if chart_of[seed] >= 0:
            continue
        chart_of[seed], members, queue = len(charts), [seed], collections.deque([seed])
        while queue:
            for t in neighbours[queue.popleft()]:
                if chart_of[t] < 0 and normal[t] @ normal[seed] > limit:
                    chart_of[t] = len(charts)
                    members.append(t)
                    queue.append(t)
        charts.append(np.array(members))
    return charts, normal, area


class Chart:
    """One chart's exact map from [0, 1)^2 onto its triangles, area-preserving."""

    def __init__(self, verts, faces, triangles, normal, area):
        n = (normal[triangles] * area[triangles, None]).sum(0)
        n /= np.linalg.norm(n)
        e1 = np.cross(n, [1.0, 0, 0] if abs(n[0]) < 0.9 else [0, 1.0, 0])
        e1 /= np.linalg.norm(e1)
        e2 = np.cross(n, e1)
        self.verts, self.faces = verts, faces[triangles]
        self.p = np.stack([verts @ e1, verts @ e2], 1)[self.faces]  # triangles x 3 x 2
        d1, d2 = self.p[:, 1] - self.p[:, 0], self.p[:, 2] - self.p[:, 0]
        plane_area = (d1[:, 0] * d2[:, 1] - d2[:, 0] * d1[:, 1]) / 2
        assert (plane_area > 0).all(), "a chart folds over"
        self.weight = area[triangles] / plane_area  # surface area per unit of plane area
        self.mass = area[triangles].sum()
        # The marginal: the weighted chord is linear in x between consecutive vertex x.
        self.xs = np.unique(self.p[:, :, 0])
        h = np.diff(self.xs)
        self.chord_left = self.chord(self.xs[:-1] + h * 1e-12)
        self.chord_right = self.chord(self.xs[1:] - h * 1e-12)
        self.cumulative = np.concatenate([[0], np.cumsum((self.chord_left + self.chord_right) / 2
                                                         * h)])

    def spans(self, x):
        """Each triangle's y interval on the vertical line at x (lo > hi where it misses)."""
        p, column = self.p, x[:, None]
        ys = []
        for i, j in ((0, 1), (1, 2), (2, 0)):
            xa, ya, xb, yb = p[:, i, 0], p[:, i, 1], p[:, j, 0], p[:, j, 1]
            dx = np.where(xb != xa, xb - xa, 1.0)
            crosses = (column >= np.minimum(xa, xb)) & (column <= np.maximum(xa, xb)) & (xb != xa)
            ys.append(np.where(crosses, ya + (column - xa) / dx * (yb - ya), np.nan))
        ys = np.stack(ys, 2)
        lo = np.min(np.where(np.isnan(ys), np.inf, ys), 2)
        hi = np.max(np.where(np.isnan(ys), -np.inf, ys), 2)
        return np.where(lo <= hi, lo, 0), np.where(lo <= hi, hi, 0)

    def chord(self, x):
        lo, hi = self.spans(x)
        return ((hi - lo) * self.weight).sum(1)

    def place(self, a, b):
        """Points on the mesh for a (share of the chart's mass along x) and b (across)."""
        target = a * self.cumulative[-1]
        i = np.clip(np.searchsorted(self.cumulative, target, side="right") - 1, 0,
                    len(self.xs) - 2)
        rest, h = target - self.cumulative[i], self.xs[i + 1] - self.xs[i]
        l0, slope = self.chord_left[i], (self.chord_right[i] - self.chord_left[i]) / h
        root = np.sqrt(np.maximum(l0 * l0 + 2 * slope * rest, 0))
        x = self.xs[i] + np.clip(np.where(l0 + root > 0, 2 * rest / (l0 + root), 0), 0, h)
        lo, hi = self.spans(x)
        along = b * ((hi - lo) * self.weight).sum(1)
        y = np.empty(len(a))
        for k in range(len(a)):  # the conditional: piecewise linear between span ends
            live = hi[k] > lo[k]
            l, u, w = lo[k][live], hi[k][live], self.weight[live]
            ends = np.sort(np.concatenate([l, u]))
            mass = (np.clip(ends[:, None] - l, 0, u - l) * w).sum(1)
            j = min(max(np.searchsorted(mass, along[k], side="right") - 1, 0), len(ends) - 2)
            step = mass[j + 1] - mass[j]
            y[k] = ends[j] + (along[k] - mass[j]) / step * (ends[j + 1] - ends[j]) if step > 0 \
                else ends[j]
        holder = np.argmax((lo <= y[:, None]) & (y[:, None] <= hi) & (hi > lo), 1)
        p = self.p[holder]
        d1, d2, d = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0], np.stack([x, y], 1) - p[:, 0]
        det = d1[:, 0] * d2[:, 1] - d2[:, 0] * d1[:, 1]
        s = (d[:, 0] * d2[:, 1] - d2[:, 0] * d[:, 1]) / det
        t = (d1[:, 0] * d[:, 1] - d[:, 0] * d1[:, 1]) / det
        f = self.faces[holder]
        v = self.verts
        return ((1 - s - t)[:, None] * v[f[:, 0]] + s[:, None] * v[f[:, 1]]
                + t[:, None] * v[f[:, 2]])


def warp(charts, a, b, max_depth=44):
    """The square onto the charts: dyadic halving over their masses, then each chart's map."""
    masses = np.array([c.mass for c in charts])
    ends = np.concatenate([[0], np.cumsum(masses)]) / masses.sum()
    n = len(a)
    depth, chart, begin = np.full(n, -1), np.zeros(n, int), np.zeros(n)
    for d in range(max_depth + 1):
        top_a = np.floor(a * 2.0 ** ((d + 1) // 2)).astype(np.int64)
        top_b = np.floor(b * 2.0 ** (d // 2)).astype(np.int64)
        t0 = np.zeros(n)
        for i in range(d):  # the node's mass begin: the coordinates' top bits interleaved
            bits, left = (top_a, (d + 1) // 2) if i % 2 == 0 else (top_b, d // 2)
            t0 += ((bits >> (left - 1 - i // 2)) & 1) * 2.0 ** -(i + 1)
        c = np.searchsorted(ends, t0, side="right") - 1
        inside = (depth < 0) & (t0 + 2.0 ** -d <= ends[np.minimum(c + 1, len(ends) - 1)])
        depth[inside], chart[inside], begin[inside] = d, c[inside], t0[inside]
        if (depth >= 0).all():
            break
    assert (depth >= 0).all()
    ra, rb = a * 2.0 ** ((depth + 1) // 2), b * 2.0 ** (depth // 2)
    ra, rb = ra - np.floor(ra), rb - np.floor(rb)
    along, across = np.where(depth % 2 == 0, ra, rb), np.where(depth % 2 == 0, rb, ra)
    share = masses[chart] / masses.sum()
    f0 = (begin - ends[chart]) / share
    f = f0 + along * 2.0 ** -depth.astype(float) / share
    out = np.empty((n, 3))
    for k, c in enumerate(charts):
        sel = chart == k
        if sel.any():
            out[sel] = c.place(np.clip(f[sel], 0, 1 - 1e-16), np.clip(across[sel], 0, 1 - 1e-16))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--cli", default=os.path.join(os.path.dirname(__file__), "..", "build",
                                                  "client", "sfcsampler"))
    ap.add_argument("--cone", type=float, default=70)
    ap.add_argument("--exponents", default="13,15,16,17")
    ap.add_argument("--seeds", type=int, default=6)
    args = ap.parse_args()
    verts, faces = icosphere(4)
    with tempfile.TemporaryDirectory() as tmp:
        mesh, out = os.path.join(tmp, "ico.obj"), os.path.join(tmp, "s.npy")
        exact = icosphere_obj(mesh)
        triangles, normal, area = grow_charts(verts, faces, args.cone)
        charts = [Chart(verts, faces, t, normal, area) for t in triangles]
        print(f"icosphere, 5120 triangles; {len(charts)} charts (cone {args.cone:g} degrees, "
              f"{min(map(len, triangles))}-{max(map(len, triangles))} triangles); g's mean "
              f"|error| over seeds 1-{args.seeds} (standard error)\n")
        print("| N | charts + scrambled Sobol | ours, sobol | ours, jittered | jittered / charts |")
        print("|---|---:|---:|---:|---:|")
        for m in map(int, args.exponents.split(",")):
            errors = collections.defaultdict(list)
            for seed in range(1, args.seeds + 1):
                ab = qmc.Sobol(2, scramble=True, seed=seed).random(1 << m)
                p = warp(charts, ab[:, 0], ab[:, 1])
                errors["charts"].append(g_quadratic(p[:, 0], p[:, 1], p[:, 2]).mean() - exact)
                for sequence in ("sobol", "jittered"):
                    subprocess.run([args.cli, "sample", "-q", "--surface", "obj:" + mesh,
                                    "--count", str(1 << m), "--seed", str(seed), "--sequence",
                                    sequence, "--format", "npy", "-o", out], check=True)
                    s = np.load(out)
                    errors[sequence].append(g_quadratic(s["x"], s["y"], s["z"]).mean() - exact)
            mean = {k: np.abs(v).mean() for k, v in errors.items()}
            cell = {k: f"{mean[k]:.2e} ({np.abs(v).std(ddof=1) / math.sqrt(len(v)):.1e})"
                    for k, v in errors.items()}
            print(f"| 2^{m} | {cell['charts']} | {cell['sobol']} | {cell['jittered']} | "
                  f"{mean['jittered'] / mean['charts']:.1f} |", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
