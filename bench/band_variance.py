#!/usr/bin/python3
"""Stratification beside the superellipsoid's singular lines (issue 19).

Counts the samples in thin parameter bands beside the lines (in the natural
angles, from the points' coordinates, so any parameterisation is judged
alike), over many seeds, for the default surface and `reparam=1`. The mean
says whether the mass is right; the standard deviation across seeds says
whether the set is still stratified there: a jittered set along the curve
has a far smaller spread than i.i.d. points (sqrt(mean)). A fix that places
the right mass but loses the stratification passes the strip check and the
Monte Carlo mean, and shows here and in the sample-anchored box slope.

Usage: bench/band_variance.py [sfcsampler] [N=24576] [seeds=8] [e=1/3]
"""
import io
import subprocess
import sys

import numpy as np


def main():
    cli = sys.argv[1] if len(sys.argv) > 1 else "build/client/sfcsampler"
    n = int(sys.argv[2]) if len(sys.argv) > 2 else 24576
    seeds = int(sys.argv[3]) if len(sys.argv) > 3 else 8
    e_text = sys.argv[4] if len(sys.argv) > 4 else "1/3"
    num, _, den = e_text.partition("/")
    e = float(num) / float(den or 1)
    boxes = {
        "equator band: u within 3e-4 of 1/2, v in [0.1, 0.6]": (0.4997, 0.5003, 0.1, 0.6),
        "longitude band: v within 1e-4 of 1/4, u in [0.1, 0.45]": (0.1, 0.45, 0.2499, 0.2501),
        "control u in [0.30, 0.31], v in [0.1, 0.6]": (0.30, 0.31, 0.1, 0.6),
    }
    counts = {}
    for surface in (f"superellipsoid:e={e_text}", f"superellipsoid:e={e_text};reparam=1"):
        for seed in range(1, seeds + 1):
            out = subprocess.run([cli, "sample", "--surface", surface, "--count", str(n),
                                  "--seed", str(seed), "-q", "-o", "-"],
                                 capture_output=True, text=True, check=True).stdout
            a = np.loadtxt(io.StringIO(out), delimiter=",", skiprows=1)
            x, y, z = a[:, 3], a[:, 4], a[:, 5]
            root = lambda c: np.sign(c) * np.abs(c) ** (1 / e)
            u = (np.arctan2(root(z), np.hypot(np.abs(x) ** (1 / e), np.abs(y) ** (1 / e))) / np.pi
                 + 0.5)
            v = np.arctan2(root(y), root(x)) / (2 * np.pi) + 0.5
            for name, (u0, u1, v0, v1) in boxes.items():
                inside = (u >= u0) & (u < u1) & (v >= v0) & (v < v1)
                counts.setdefault((surface, name), []).append(int(inside.sum()))
    print(f"N = {n}, seeds 1..{seeds}: samples in each band, mean and standard deviation across "
          "seeds\n")
    print("| surface | band | mean | SD across seeds | i.i.d. SD |\n|---|---|---:|---:|---:|")
    for (surface, name), c in counts.items():
        c = np.array(c)
        print(f"| {surface} | {name} | {c.mean():.1f} | {c.std(ddof=1):.1f} | "
              f"{np.sqrt(c.mean()):.1f} |")


if __name__ == "__main__":
    main()
