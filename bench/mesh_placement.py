#!/usr/bin/python3
"""Issue 19's mesh gap on the real sampler: the icosphere's own samples
(`sfcsampler sample --triangle`), and the same samples moved inside their
own triangles (to a uniform random point, or to the centroid), all projected
to the unit sphere and scored by the spherical-triangle discrepancy (128
random triangles per seed), N = 64..6144, against the built-in sphere.

If moving each sample to a random point of its own triangle leaves the slope
unchanged, the sampler's in-triangle placement behaves as if independent of
the curve; if the centroid (curve-order only) is steeper, the placement
costs the slope, not the triangle order.

Usage: bench/mesh_placement.py MESH.ply [sfcsampler] [seeds=1,2,3]
"""
import io
import subprocess
import sys

import numpy as np


def read_ply(path):
    data = open(path, "rb").read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode()
    nv = int(header.split("element vertex ")[1].split()[0])
    nf = int(header.split("element face ")[1].split()[0])
    nprops = header.split("element face")[0].count("property double")
    v = np.frombuffer(data, dtype="<f8", count=nv * nprops, offset=end).reshape(nv, nprops)[:, :3]
    f = np.frombuffer(data, dtype=np.dtype([("n", "u1"), ("i", "<i4", 3)]), count=nf,
                      offset=end + nv * nprops * 8)
    return v, f["i"]


def sample(cli, surface, n, seed):
    out = subprocess.run([cli, "sample", "--surface", surface, "--count", str(n), "--seed",
                          str(seed), "-q", "-o", "-"]
                         + (["--triangle"] if surface.startswith("ply:") else []),
                         check=True, capture_output=True, text=True).stdout
    return np.loadtxt(io.StringIO(out), delimiter=",", skiprows=1, ndmin=2)


def random_unit(rng, k):
    z = 1 - 2 * rng.random(k)
    phi = 2 * np.pi * rng.random(k)
    s = np.sqrt(1 - z * z)
    return np.stack([s * np.cos(phi), s * np.sin(phi), z], axis=1)


def spherical_discrepancy(p, seed, triangles=128):
    rng = np.random.default_rng(1000 + seed)
    a, b, c = random_unit(rng, triangles), random_unit(rng, triangles), random_unit(rng, triangles)
    flip = np.einsum("ij,ij->i", a, np.cross(b, c)) < 0
    b[flip], c[flip] = c[flip].copy(), b[flip].copy()
    triple = np.einsum("ij,ij->i", a, np.cross(b, c))
    excess = 2 * np.arctan2(triple, 1 + np.einsum("ij,ij->i", a, b) + np.einsum("ij,ij->i", b, c)
                            + np.einsum("ij,ij->i", c, a))
    inside = ((p @ np.cross(a, b).T >= 0) & (p @ np.cross(b, c).T >= 0) &
              (p @ np.cross(c, a).T >= 0))
    return np.max(np.abs(inside.mean(axis=0) - excess / (4 * np.pi)))


def main():
    mesh = sys.argv[1]
    cli = sys.argv[2] if len(sys.argv) > 2 else "build/client/sfcsampler"
    seeds = [int(s) for s in (sys.argv[3] if len(sys.argv) > 3 else "1,2,3").split(",")]
    verts, faces = read_ply(mesh)
    sizes = [n for l in range(6, 13) for n in (2 ** l, 3 * 2 ** (l - 1)) if n <= 6144]
    slopes = {}
    for seed in seeds:
        rng = np.random.default_rng(seed)
        d = {}
        for n in sizes:
            s = sample(cli, "sphere", n, seed)
            d.setdefault("built-in sphere", []).append(spherical_discrepancy(s[:, 3:6], seed))
            m = sample(cli, "ply:" + mesh, n, seed)
            tri = faces[m[:, 6].astype(int)]
            p0, p1, p2 = verts[tri[:, 0]], verts[tri[:, 1]], verts[tri[:, 2]]
            variants = {"mesh, as sampled": m[:, 3:6],
                        "mesh, moved to the triangle centroid": (p0 + p1 + p2) / 3}
            a, b = rng.random(n), rng.random(n)
            flip = a + b > 1
            a[flip], b[flip] = 1 - a[flip], 1 - b[flip]
            variants["mesh, moved to a random point of the triangle"] = (
                p0 + (p1 - p0) * a[:, None] + (p2 - p0) * b[:, None])
            for name, p in variants.items():
                p = p / np.linalg.norm(p, axis=1)[:, None]
                d.setdefault(name, []).append(spherical_discrepancy(p, seed))
        for name, ds in d.items():
            slopes.setdefault(name, []).append(np.polyfit(np.log(sizes), np.log(ds), 1)[0])
        print(f"seed {seed} done", file=sys.stderr)
    print(f"Spherical-triangle discrepancy slope, N = {sizes[0]}..{sizes[-1]}, seeds "
          f"{','.join(map(str, seeds))} (mean +- SE)\n\n| set | slope |\n|---|---:|")
    for name, v in slopes.items():
        v = np.array(v)
        se = v.std(ddof=1) / np.sqrt(len(v)) if len(v) > 1 else 0
        print(f"| {name} | {v.mean():.3f} +- {se:.3f} |")


if __name__ == "__main__":
    main()
