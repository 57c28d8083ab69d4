#!/usr/bin/python3
"""Why `--sequence sobol` on a mesh is about as good as `jittered` and no better (issue 36).

The mesh warp (mesh/mesh_warp.h) halves the unit square at 1/2 and the mass along the curve with
it, so the box of a leaf's share is a box of the net and every 2^m block fills it exactly; inside
it, the share is a smooth map of the box. The error is then the sum over boxes of a smooth map's
quasi-Monte Carlo error, each box holding n points: about size x n^-1.3 each, so per unit of mass
it falls only as n^-0.3, and a triangle cut into several shares pays for each. This script
measures that on flat meshes of the unit square, where the integral of
f = exp(x) cos(y) is (e - 1) sin 1, and on the icosphere of bench/sobol_integration.py (its g):
  * 16 x 16 squares, 512 equal triangles: every leaf is a whole box (n = 128 at N = 2^16);
  * 16 x 12 squares, 384 equal triangles: leaves of 1/384 are cut into dyadic shares;
  * 16 x 16 squares with the inner vertices moved up to 0.3 of a square: unequal areas;
  * the icosphere of 5120 triangles, n = 12.8.
RMS error over seeds 1-12 of sobol and jittered at N = 2^16.

Usage: /usr/bin/python3 bench/sobol_mesh_study.py [--cli build/client/sfcsampler] [--seeds 12]
"""
import argparse
import math
import os
import subprocess
import sys
import tempfile

import numpy as np

from sobol_integration import g_quadratic, icosphere_obj


def grid_obj(path, gx, gy, move=0.0, seed=0):
    """The unit square as gx x gy squares of two triangles each (z = 0), inner vertices moved
    by up to `move` of a square."""
    rng = np.random.default_rng(seed)
    x, y = np.meshgrid(np.linspace(0, 1, gx + 1), np.linspace(0, 1, gy + 1), indexing="ij")
    inner = np.zeros(x.shape, bool)
    inner[1:-1, 1:-1] = True
    x = x + inner * rng.uniform(-move, move, x.shape) / gx
    y = y + inner * rng.uniform(-move, move, y.shape) / gy
    with open(path, "w") as fh:
        for i in range(gx + 1):
            for j in range(gy + 1):
                fh.write(f"v {x[i, j]:.17g} {y[i, j]:.17g} 0\n")
        def at(i, j):
            return i * (gy + 1) + j + 1
        for i in range(gx):
            for j in range(gy):
                fh.write(f"f {at(i, j)} {at(i + 1, j)} {at(i + 1, j + 1)}\n"
                         f"f {at(i, j)} {at(i + 1, j + 1)} {at(i, j + 1)}\n")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--cli", default=os.path.join(os.path.dirname(__file__), "..", "build",
                                                  "client", "sfcsampler"))
    ap.add_argument("--seeds", type=int, default=12)
    ap.add_argument("--count", type=int, default=1 << 16)
    args = ap.parse_args()
    plane_exact = (math.e - 1) * math.sin(1)
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "s.npy")
        cases = []
        for name, gx, gy, move in (("512 equal triangles", 16, 16, 0.0),
                                   ("384 equal triangles", 16, 12, 0.0),
                                   ("512 unequal triangles", 16, 16, 0.3)):
            path = os.path.join(tmp, f"grid{gx}x{gy}_{move}.obj")
            grid_obj(path, gx, gy, move)
            cases.append((name, path, lambda a: np.exp(a["x"]) * np.cos(a["y"]), plane_exact))
        ico = os.path.join(tmp, "ico.obj")
        cases.append(("icosphere, 5120 triangles", ico,
                      lambda a: g_quadratic(a["x"], a["y"], a["z"]), icosphere_obj(ico)))
        print(f"N = {args.count}, RMS error over seeds 1-{args.seeds}\n")
        print("| mesh | sobol | jittered | jittered / sobol |\n|---|---:|---:|---:|")
        for name, path, func, exact in cases:
            rms = {}
            for sequence in ("sobol", "jittered"):
                errors = []
                for seed in range(1, args.seeds + 1):
                    subprocess.run([args.cli, "sample", "-q", "--surface", "obj:" + path,
                                    "--count", str(args.count), "--seed", str(seed), "--sequence",
                                    sequence, "--format", "npy", "-o", out], check=True)
                    errors.append(float(func(np.load(out)).mean()) - exact)
                rms[sequence] = math.sqrt(np.mean(np.square(errors)))
            print(f"| {name} | {rms['sobol']:.2e} | {rms['jittered']:.2e} | "
                  f"{rms['jittered'] / rms['sobol']:.1f} |", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
