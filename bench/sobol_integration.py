#!/usr/bin/python3
"""Integration with `--sequence sobol` against `jittered`, from the CLI's output (issue 36).

Every exact value here is computed by this script alone, from the surfaces' formulas
(core/builtin_surfaces.cc), never from the sampler:
  * sphere (unit radius): the mean of f = x^2 + 0.3 y z + exp(z) over the area is
    (4 pi / 3 + 2 pi (e - 1/e)) / (4 pi);
  * torus R = 2, r = 1: a periodic trapezoid rule (512 x 512 nodes, spectrally exact) of f
    times the area element r (R + r cos b);
  * superellipsoid (the default, e = 1/3): Gauss-Legendre on each quarter of both angles,
    after the substitution angle = quarter start + pi/2 t^3 / (t^3 + (1 - t)^3), which makes
    the singular lines smooth (the paper's reparameterisation, Sect. 5.3); checked against
    the closed form of the mean of x^2, 0.4923582 (docs/QUALITY.md);
  * an icosphere mesh written here (icosahedron, 4 subdivisions, 5120 triangles, as OBJ): the
    exact integral of the quadratic g = x^2 + 0.3 y z + z over its flat triangles (the
    edge-midpoint rule is exact for quadratics).

It prints the issue's 'What must hold':
  1. sphere and torus, f, N = 8192: mean |error| over seeds 1-5 <= 1e-5;
  2. superellipsoid (f) and the mesh (g) at N = 2^16: sobol's mean |error| over seeds 1-3 at
     most a fifth of jittered's;
  3. speed: the CLI writing 10^6 sphere samples (NPY to /dev/null), best of 3, sobol within
     2x of jittered.
With --step-sphere FILE (a STEP sphere centred at the origin, of radius --step-radius, as
build/cad/make_cad_fixtures writes: radius 10) it also reports f on that CAD model, its points
scaled to the unit sphere, against the sphere's closed form (N = 8192 and 2^16, seeds 1-3).
The plane's rectangle discrepancy is bench/sphere_discrepancy.py's:
  /usr/bin/python3 bench/sphere_discrepancy.py --surface plane --variant sobol="--sequence sobol"

`sfcsampler eval --sections quality --quality-sections integration` prints the same surfaces'
table for every mode (jittered, sobol, progressive) from exact means of its own
(evaluation/integration.h), with slopes and the points and time to reach 1e-4 and 1e-5.

Usage: /usr/bin/python3 bench/sobol_integration.py [--cli build/client/sfcsampler] [--quick]
"""
import argparse
import math
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

from compare_samplers import icosphere


def f_smooth(x, y, z):
    return x * x + 0.3 * y * z + np.exp(z)


def g_quadratic(x, y, z):
    return x * x + 0.3 * y * z + z


def sphere_exact():
    return (4 * math.pi / 3 + 2 * math.pi * (math.e - 1 / math.e)) / (4 * math.pi)


def torus_exact(R=2.0, r=1.0, m=512):
    a = 2 * math.pi * np.arange(m) / m
    b = 2 * math.pi * np.arange(m) / m
    A, B = np.meshgrid(a, b, indexing="ij")
    w = R + r * np.cos(B)
    x, y, z = w * np.cos(A), w * np.sin(A), r * np.sin(B)
    dA = r * w
    return float((f_smooth(x, y, z) * dA).sum() / dA.sum())


def superellipsoid_mean(func, e=1 / 3, nodes=256):
    """The mean of func over the superellipsoid x = C(a) C(b), y = C(a) S(b), z = S(a) with
    C = signed cos^e, S = signed sin^e, a in [-pi/2, pi/2], b in [-pi, pi]."""
    t, wt = np.polynomial.legendre.leggauss(nodes)
    t, wt = (t + 1) / 2, wt / 2
    q = t ** 3 + (1 - t) ** 3
    s = t ** 3 / q                                   # [0, 1] -> [0, 1]
    ds = 3 * t ** 2 * (1 - t) ** 2 / q ** 2          # its derivative
    # Cosine and sine of each node's angle, accurate beside the quarter ends, where
    # the signed powers are singular: quarter k starts at lo + k pi/2, a rotation by
    # a multiple of pi/2 is exact, and the offset from the nearer end is formed
    # without cancellation (1 - s = (1 - t)^3 / q).
    d_lo, d_hi = math.pi / 2 * s, math.pi / 2 * ((1 - t) ** 3 / q)
    near_lo = s < 0.5
    cd = np.where(near_lo, np.cos(d_lo), np.sin(d_hi))
    sd = np.where(near_lo, np.sin(d_lo), np.cos(d_hi))
    def pieces(lo_quarters, count):
        cs, ss, dang, wts = [], [], [], []
        for k in range(count):
            c0, s0 = [(1, 0), (0, 1), (-1, 0), (0, -1)][(lo_quarters + k) % 4]
            cs.append(c0 * cd - s0 * sd)
            ss.append(s0 * cd + c0 * sd)
            dang.append(math.pi / 2 * ds)
            wts.append(wt)
        return np.concatenate(cs), np.concatenate(ss), np.concatenate(dang), np.concatenate(wts)
    ca, sa, da, wa = pieces(-1, 2)   # a from -pi/2
    cb, sb, db, wb = pieces(-2, 4)   # b from -pi
    def spow(c):
        return np.sign(c) * np.abs(c) ** e
    def dspow(c, dc):  # d/dx sign(c)|c|^e = e |c|^(e-1) c'
        return e * np.abs(c) ** (e - 1) * dc
    G, F, H, S = spow(ca), spow(sa), spow(cb), spow(sb)
    Ga, Fa = dspow(ca, -sa) * da, dspow(sa, ca) * da   # per unit t of the a-substitution
    Hb, Sb = dspow(cb, -sb) * db, dspow(sb, cb) * db
    G2, H2 = G[:, None], H[None, :]
    x, y, z = G2 * H2, G2 * S[None, :], np.broadcast_to(F[:, None], (len(ca), len(cb)))
    xa, ya, za = Ga[:, None] * H2, Ga[:, None] * S[None, :], np.broadcast_to(Fa[:, None], x.shape)
    xb, yb = G2 * Hb[None, :], G2 * Sb[None, :]
    nx, ny, nz = ya * 0 - za * yb, za * xb - xa * 0, xa * yb - ya * xb
    dA = np.sqrt(nx ** 2 + ny ** 2 + nz ** 2) * wa[:, None] * wb[None, :]
    return float((func(x, y, z) * dA).sum() / dA.sum())


def icosphere_obj(path, subdivisions=4):
    """Writes compare_samplers' icosphere as OBJ; returns f's exact mean over its flat
    triangles (the midpoint rule is exact for a quadratic)."""
    verts, faces = icosphere(subdivisions)
    with open(path, "w") as fh:
        for p in verts:
            fh.write("v %.17g %.17g %.17g\n" % tuple(p))
        for a, b, c in faces:
            fh.write("f %d %d %d\n" % (a + 1, b + 1, c + 1))
    V, F = np.array(verts), np.array(faces)
    A, B, C = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
    area = np.linalg.norm(np.cross(B - A, C - A), axis=1) / 2
    def g(p):
        return g_quadratic(p[:, 0], p[:, 1], p[:, 2])
    integral = area / 3 * (g((A + B) / 2) + g((B + C) / 2) + g((C + A) / 2))
    return float(integral.sum() / area.sum())


class Cli:
    def __init__(self, path, tmp):
        self.path, self.out = path, os.path.join(tmp, "s.npy")

    def sample(self, surface, n, seed, sequence):
        subprocess.run([self.path, "sample", "-q", "--surface", surface, "--count", str(n),
                        "--seed", str(seed), "--sequence", sequence, "--format", "npy",
                        "-o", self.out], check=True)
        return np.load(self.out)

    def mean_error(self, surface, n, seeds, sequence, func, exact, scale=1.0):
        errs = []
        for seed in seeds:
            a = self.sample(surface, n, seed, sequence)
            assert len(a) == n, (surface, n, len(a))
            x, y, z = a["x"] / scale, a["y"] / scale, a["z"] / scale
            errs.append(abs(float(func(x, y, z).mean()) - exact))
        errs = np.array(errs)
        return errs.mean(), errs.std(ddof=1) / math.sqrt(len(errs)) if len(errs) > 1 else 0.0

    def seconds(self, surface, n, sequence, repeats=3):
        best = math.inf
        for _ in range(repeats):
            t0 = time.perf_counter()
            subprocess.run([self.path, "sample", "-q", "--surface", surface, "--count", str(n),
                            "--sequence", sequence, "--format", "npy", "-o", "/dev/null"],
                           check=True)
            best = min(best, time.perf_counter() - t0)
        return best


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--cli", default=os.path.join(os.path.dirname(__file__), "..", "build",
                                                  "client", "sfcsampler"))
    ap.add_argument("--quick", action="store_true", help="smaller N, for a smoke test")
    ap.add_argument("--step-sphere", help="a STEP sphere centred at the origin")
    ap.add_argument("--step-radius", type=float, default=10.0)
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        cli = Cli(args.cli, tmp)
        ok = True
        def check(name, value, target, passed):
            nonlocal ok
            ok = ok and passed
            print(f"| {name} | {value} | {target} | {'PASS' if passed else 'FAIL'} |")

        check_x2 = superellipsoid_mean(lambda x, y, z: x * x)
        exact = {"sphere": sphere_exact(), "torus:R=2;r=1": torus_exact(),
                 "superellipsoid": superellipsoid_mean(f_smooth)}
        mesh = os.path.join(tmp, "ico.obj")
        mesh_exact = icosphere_obj(mesh)
        print(f"exact means: sphere {exact['sphere']:.15g}, torus {exact['torus:R=2;r=1']:.15g}, "
              f"superellipsoid {exact['superellipsoid']:.12g} (its x^2: {check_x2:.9f}, closed "
              f"form 0.4923582), icosphere-4 mesh g {mesh_exact:.15g}\n")
        print("| check | measured | target | |\n|---|---|---|---|")
        n1 = 1024 if args.quick else 8192
        for surface in ("sphere", "torus:R=2;r=1"):
            m, se = cli.mean_error(surface, n1, range(1, 6), "sobol", f_smooth, exact[surface])
            mj, sej = cli.mean_error(surface, n1, range(1, 6), "jittered", f_smooth,
                                     exact[surface])
            check(f"{surface}, f, N = {n1}, seeds 1-5", f"sobol {m:.2e} +- {se:.1e} (jittered "
                  f"{mj:.2e} +- {sej:.1e})", "<= 1e-5", m <= 1e-5)
        n2 = 4096 if args.quick else 1 << 16
        for surface, func, value in (("superellipsoid", f_smooth, exact["superellipsoid"]),
                                     (f"obj:{mesh}", g_quadratic, mesh_exact)):
            m, se = cli.mean_error(surface, n2, range(1, 4), "sobol", func, value)
            mj, sej = cli.mean_error(surface, n2, range(1, 4), "jittered", func, value)
            name = "superellipsoid, f" if surface == "superellipsoid" else "icosphere mesh, g"
            check(f"{name}, N = {n2}, seeds 1-3", f"sobol {m:.2e} +- {se:.1e}, jittered "
                  f"{mj:.2e} +- {sej:.1e}: {mj / m:.1f}x", "sobol <= jittered / 5",
                  m <= mj / 5)
        if args.step_sphere:
            for n in ((1024, 8192) if args.quick else (8192, 1 << 16)):
                m, se = cli.mean_error(f"step:{args.step_sphere}", n, range(1, 4), "sobol",
                                       f_smooth, exact["sphere"], args.step_radius)
                mj, sej = cli.mean_error(f"step:{args.step_sphere}", n, range(1, 4), "jittered",
                                         f_smooth, exact["sphere"], args.step_radius)
                print(f"| STEP sphere, f, N = {n}, seeds 1-3 | sobol {m:.2e} +- {se:.1e}, "
                      f"jittered {mj:.2e} +- {sej:.1e}: {mj / m:.1f}x | (no target) | INFO |")
        n3 = 100000 if args.quick else 1000000
        ts, tj = cli.seconds("sphere", n3, "sobol"), cli.seconds("sphere", n3, "jittered")
        check(f"speed, sphere, N = {n3}, best of 3", f"sobol {ts:.3f} s, jittered {tj:.3f} s: "
              f"{ts / tj:.2f}x", "<= 2x", ts <= 2 * tj)
        return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
