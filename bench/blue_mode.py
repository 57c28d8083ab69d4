#!/usr/bin/python3
"""The blue sequence's figures (issue 35) from one run, with its peers.

Prints, each as a table row with the mean and standard error over seeds:
  - plane and sphere, N = 4096: the minimum and mean nearest-neighbour
    distance relative to hexagonal packing (unit square, Euclidean; unit
    sphere, chord, area 4 pi), for blue and jittered;
  - exact N, and 8 shards of a torus against the whole run's bytes (CLI, NPY);
  - density expr:u+v on the plane: the share of samples with u < 0.3 against
    its mass 0.195 (N = 100 000; u < 1/2 would be a union of whole curve runs,
    exact for any stratified set);
  - Monte Carlo bias: the mean of f = exp(u) v^2 on the plane (closed form
    (e - 1) / 3) and of z^2 on the sphere (1/3), N = 4096, 20 seeds, blue and
    jittered: mean error +- SE of the mean (a bias shows as a mean error many
    SEs from 0);
  - time of 10^6 sphere samples in process (embedded Python, one thread, tree
    cached), blue against jittered, best of 3;
  - peers on the same mesh and count (an icosphere of 20 480 triangles, unit
    radius, N = 4096 and 20 000): Open3D's sample_points_poisson_disk and
    ours (ply: mesh, --sequence blue), seconds and the two distances; scipy's
    qmc.PoissonDisk on the unit square at N = 4096 (it returns fewer points
    than asked: the count is shown);
  - the radially averaged power spectrum (periodogram over integer wave
    vectors, white noise P = 1) of the plane sets at N = 4096: ours blue and
    jittered, 2D jittered, scrambled Sobol and scipy's PoissonDisk: the mean P
    below f = sqrt(N)/2 and the peak beyond it (Open3D's sets lie on a mesh,
    where a periodogram of the square does not apply).

Usage: PYTHONPATH=build/python /usr/bin/python3 bench/blue_mode.py [--build build]
       [--seeds 1,2,3] [--quick] [--only figures,speed,peers,spectra]
Needs Debian's python3-numpy, python3-scipy and python3-open3d.
"""
import argparse
import io
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

from seed_stats import mean_se
from spacing import hex_spacing, nn


def fmt(values, digits=3):
    m, se = mean_se(values)
    return f"{m:.{digits}f} +- {se:.{digits}f}"


def cli_npy(cli, args):
    with tempfile.NamedTemporaryFile(suffix=".npy") as f:
        subprocess.run([cli, "sample", "-q", "--format", "npy", "-o", f.name] + args, check=True)
        with open(f.name, "rb") as g:
            raw = g.read()
        return np.load(io.BytesIO(raw)), raw


def icosphere_ply(path, subdivisions):
    import open3d as o3d
    mesh = o3d.geometry.TriangleMesh.create_sphere(radius=1.0, resolution=subdivisions)
    o3d.io.write_triangle_mesh(path, mesh)
    v = np.asarray(mesh.vertices)
    t = np.asarray(mesh.triangles)
    area = 0.5 * np.linalg.norm(np.cross(v[t[:, 1]] - v[t[:, 0]], v[t[:, 2]] - v[t[:, 0]]),
                                axis=1).sum()
    return mesh, area


def spectrum(points, fmax):
    """P(f), f = 1 .. fmax: |sum_j exp(-2 pi i k.x_j)|^2 / N averaged over |k| rounding to f."""
    k = np.arange(-fmax, fmax + 1)
    ex = np.exp(-2j * np.pi * np.outer(k, points[:, 0]))
    ey = np.exp(-2j * np.pi * np.outer(np.arange(0, fmax + 1), points[:, 1]))
    p = np.abs(ex @ ey.T) ** 2 / len(points)  # [kx + fmax, ky]
    kx, ky = np.meshgrid(k, np.arange(0, fmax + 1), indexing="ij")
    f = np.rint(np.hypot(kx, ky)).astype(int)
    keep = (ky > 0) | (kx > 0)
    out = np.zeros(fmax + 1)
    for i in range(1, fmax + 1):
        sel = keep & (f == i)
        out[i] = p[sel].mean()
    return out[1:]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--build", default="build")
    ap.add_argument("--seeds", default="1,2,3")
    ap.add_argument("--quick", action="store_true", help="fewer seeds for the bias, no N = 20 000")
    ap.add_argument("--only", default="figures,speed,peers,spectra")
    args = ap.parse_args()
    only = set(args.only.split(","))
    cli = os.path.join(args.build, "client", "sfcsampler")
    seeds = [int(s) for s in args.seeds.split(",")]
    n = 4096

    if "figures" in only:
        figures(cli, seeds, n, args)
    if "speed" in only:
        speed()
    if "peers" in only:
        peers(cli, n, args)
    if "spectra" in only:
        spectra(cli, seeds, n)


def spectra(cli, seeds, n):
    from scipy.stats import qmc
    fmax = int(1.5 * np.sqrt(n))
    print(f"\n## Radially averaged power spectrum, plane, N = {n}, seeds {seeds}, f to {fmax}\n")
    print("| set | mean P, f < sqrt(N)/2 | peak P | peak at f / sqrt(N) |\n|---|---:|---:|---:|")
    sets = {}
    for seed in seeds:
        rng = np.random.default_rng(seed)
        for seq in ("blue", "jittered"):
            a, _ = cli_npy(cli, ["--surface", "plane", "--count", str(n), "--seed", str(seed),
                                 "--sequence", seq])
            sets.setdefault(f"ours, {seq}", []).append(np.stack([a["u"], a["v"]], axis=1))
        k = int(np.sqrt(n))
        i, j = np.meshgrid(np.arange(k), np.arange(k), indexing="ij")
        sets.setdefault("2D jittered", []).append(
            np.stack([(i.ravel() + rng.random(n)) / k, (j.ravel() + rng.random(n)) / k], axis=1))
        sets.setdefault("scrambled Sobol (scipy)", []).append(
            qmc.Sobol(d=2, scramble=True, seed=seed).random(n))
        sets.setdefault("scipy PoissonDisk r = 0.80 (its own count)", []).append(
            qmc.PoissonDisk(d=2, radius=0.80 * hex_spacing(n, 1.0), seed=seed).random(n))
    root = np.sqrt(n)
    for name, pts in sets.items():
        p = np.mean([spectrum(x, fmax) for x in pts], axis=0)
        f = np.arange(1, fmax + 1)
        low = p[f < root / 2].mean()
        hi = f >= root / 2
        peak = f[hi][np.argmax(p[hi])]
        print(f"| {name} | {low:.3f} | {p[peak - 1]:.2f} | {peak / root:.2f} |")


def figures(cli, seeds, n, args):
    print(f"## Blue sequence (issue 35), seeds {args.seeds}\n")
    print("| figure | blue | jittered | must hold (blue) |\n|---|---:|---:|---|")
    for surface, area, need in (("plane", 1.0, "min >= 0.75, mean >= 0.80"),
                                ("sphere", 4 * np.pi, "min >= 0.72, mean >= 0.79")):
        rows = {"blue": ([], []), "jittered": ([], [])}
        for seq in rows:
            for seed in seeds:
                a, _ = cli_npy(cli, ["--surface", surface, "--count", str(n), "--seed", str(seed),
                                     "--sequence", seq])
                assert len(a) == n, f"{len(a)} samples, not {n}"
                pts = np.stack([a["u"], a["v"]] if surface == "plane" else
                               [a["x"], a["y"], a["z"]], axis=1)
                lo, mean = nn(pts, area)
                rows[seq][0].append(lo)
                rows[seq][1].append(mean)
        print(f"| {surface} N = {n}: min NN / hexagonal | {fmt(rows['blue'][0])} | "
              f"{fmt(rows['jittered'][0])} | {need} |")
        print(f"| {surface} N = {n}: mean NN / hexagonal | {fmt(rows['blue'][1])} | "
              f"{fmt(rows['jittered'][1])} | |")

    # Exact N and shards = whole run.
    torus = ["--surface", "torus:R=1;r=0.4", "--count", "50000", "--seed", "7", "--sequence",
             "blue"]
    whole, _ = cli_npy(cli, torus)
    parts = [cli_npy(cli, torus + ["--shard", f"{i}/8"])[0] for i in range(8)]
    joined = np.concatenate(parts)
    same = len(joined) == len(whole) and joined.tobytes() == whole.tobytes()
    print(f"| torus N = 50 000: samples; 8 shards concatenated = whole run's bytes | "
          f"{len(whole)}; {'yes' if same else 'NO'} | | exact N; yes |")

    # Density split.
    shares = {"blue": [], "jittered": []}
    for seq in shares:
        for seed in seeds:
            a, _ = cli_npy(cli, ["--surface", "plane", "--density", "expr:u+v", "--count",
                                 "100000", "--seed", str(seed), "--sequence", seq])
            shares[seq].append((a["u"] < 0.3).mean() - 0.195)
    print(f"| u+v on the plane, N = 100 000: share(u < 0.3) - 0.195 | "
          f"{fmt(shares['blue'], 5)} | {fmt(shares['jittered'], 5)} | within noise |")

    # Monte Carlo bias.
    bias_seeds = range(1, 6 if args.quick else 21)
    for surface, label, f, exact in (
            ("plane", "mean of exp(u) v^2 - (e-1)/3", lambda a: np.exp(a["u"]) * a["v"] ** 2,
             (np.e - 1) / 3),
            ("sphere", "mean of z^2 - 1/3", lambda a: a["z"] ** 2, 1 / 3)):
        err = {"blue": [], "jittered": []}
        for seq in err:
            for seed in bias_seeds:
                a, _ = cli_npy(cli, ["--surface", surface, "--count", str(n), "--seed", str(seed),
                                     "--sequence", seq])
                err[seq].append(f(a).mean() - exact)
        print(f"| {surface} N = {n}, {len(bias_seeds)} seeds: {label} | {fmt(err['blue'], 7)} | "
              f"{fmt(err['jittered'], 7)} | measured, reported |")



def speed():
    """10^6 sphere samples in process, one thread, tree cached."""
    try:
        import sfcsampler
        s = sfcsampler.Sampler(threads=1)
        best = {}
        for seq in ("jittered", "blue"):
            s.sample(surface="sphere", count=10**6, sequence=seq, seed=1)  # tree built, cached
            times = []
            for _ in range(3):
                t0 = time.perf_counter()
                got = s.sample(surface="sphere", count=10**6, sequence=seq, seed=1)
                times.append(time.perf_counter() - t0)
                assert len(got) == 10**6
            best[seq] = min(times)
        print(f"| sphere 10^6 in process, 1 thread: seconds (samples/s) | {best['blue']:.3f} "
              f"({1e6 / best['blue'] / 1e6:.2f} M/s) | {best['jittered']:.3f} | "
              f"<= 5x jittered ({best['blue'] / best['jittered']:.1f}x), >= 1 M/s |")
    except ImportError:
        print("| sphere 10^6 in process | (PYTHONPATH=build/python needed) | | |")



def peers(cli, n, args):
    print("\n## Peers: speed and nearest-neighbour distances / hexagonal\n")
    print("| set | surface | N asked | N given | seconds | min | mean |\n|---|---|---:|---:|---:|"
          "---:|---:|")
    import open3d as o3d
    from scipy.stats import qmc
    with tempfile.TemporaryDirectory() as tmp:
        ply = os.path.join(tmp, "sphere.ply")
        mesh, area = icosphere_ply(ply, 64)
        tri = len(mesh.triangles)
        for count in ((4096,) if args.quick else (4096, 20000)):
            t0 = time.perf_counter()
            a, _ = cli_npy(cli, ["--surface", f"ply:{ply}", "--count", str(count), "--seed", "1",
                                 "--sequence", "blue"])
            t_ours = time.perf_counter() - t0
            lo, mean = nn(np.stack([a["x"], a["y"], a["z"]], axis=1), area)
            print(f"| ours, blue (CLI, incl. start and mesh read) | mesh, {tri} triangles | "
                  f"{count} | {len(a)} | {t_ours:.3f} | {lo:.3f} | {mean:.3f} |")
            o3d.utility.random.seed(1)
            t0 = time.perf_counter()
            pc = mesh.sample_points_poisson_disk(count)
            t_o3d = time.perf_counter() - t0
            p = np.asarray(pc.points)
            lo, mean = nn(p, area)
            print(f"| Open3D sample_points_poisson_disk | mesh, {tri} triangles | {count} | "
                  f"{len(p)} | {t_o3d:.3f} | {lo:.3f} | {mean:.3f} |")
    for r in (0.80,):
        t0 = time.perf_counter()
        p = qmc.PoissonDisk(d=2, radius=r * hex_spacing(n, 1.0), seed=1).random(n)
        t_sp = time.perf_counter() - t0
        lo, mean = nn(p, 1.0)
        print(f"| scipy qmc.PoissonDisk radius {r:.2f} (by its own count) | unit square | {n} | "
              f"{len(p)} | {t_sp:.3f} | {lo:.3f} | {mean:.3f} |")
    t0 = time.perf_counter()
    a, _ = cli_npy(cli, ["--surface", "plane", "--count", str(n), "--seed", "1", "--sequence",
                         "blue"])
    t_ours = time.perf_counter() - t0
    lo, mean = nn(np.stack([a["u"], a["v"]], axis=1), 1.0)
    print(f"| ours, blue (CLI) | unit square | {n} | {len(a)} | {t_ours:.3f} | {lo:.3f} | "
          f"{mean:.3f} |")


if __name__ == "__main__":
    sys.exit(main())
