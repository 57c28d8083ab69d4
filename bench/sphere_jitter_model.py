#!/usr/bin/python3
"""A model of the sphere's jittered curve samples, to test what sets its discrepancy slope.

Mass-exact jittered samples along a Hilbert order of a fine grid of parameter cells, with no
tree, no leaf models and no warps: sample k's mass coordinate is (k + U_k) / N, the cell holding
it is found by its running mass, and inside the cell the sample is placed exactly by area
(theta = pi u, phi = 2 pi v: uniform in cos(theta), uniform in phi). Each variant changes one
thing, measured on the same triangles (bench/sphere_discrepancy.py's measure and budget):

  curve    the built-in sphere's layout: one Hilbert square over (u, v)
  wide     two Hilbert squares side by side along v, so each cell is twice as long in u as in
           v and maps to a square at the equator (the default's are 2:1 there)
  octa     an equal-area octahedral map of the unit square (Clarberg 2008), whose cells are
           nearly isotropic everywhere, uniform mass
  ri       offsets U_k = Owen-scrambled base-2 radical inverse of k (consecutive strata's
           offsets spread apart), 'curve' layout
  anti     antithetic offsets, U_(2i+1) = 1 - U_(2i), 'curve' layout

  /usr/bin/python3 bench/sphere_jitter_model.py                  # every variant, quick budget
  /usr/bin/python3 bench/sphere_jitter_model.py curve wide --seeds 1,2,3 --full
"""
import argparse
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import sphere_discrepancy as sd  # noqa: E402


def hilbert_d2xy(m, d):
    """Hilbert index d -> cell (x, y) of an m x m grid (m a power of 2), from (0,0) to (m-1,0)."""
    x = np.zeros_like(d)
    y = np.zeros_like(d)
    t = d.copy()
    s = 1
    while s < m:
        rx = 1 & (t // 2)
        ry = 1 & (t ^ rx)
        swap = ry == 0
        flip = swap & (rx == 1)
        x = np.where(flip, s - 1 - x, x)
        y = np.where(flip, s - 1 - y, y)
        x, y = np.where(swap, y, x), np.where(swap, x, y)
        x = x + s * rx
        y = y + s * ry
        t //= 4
        s *= 2
    return x, y


def owen_radical_inverse(n, rng, bits=24):
    """Owen-scrambled base-2 radical inverse of 0..n-1 (nested flips per prefix), plus uniform
    bits below 2^-bits."""
    k = np.arange(n, dtype=np.int64)
    r = np.zeros(n, dtype=np.int64)
    for i in range(bits):
        r |= ((k >> i) & 1) << (bits - 1 - i)
    out = np.zeros(n, dtype=np.int64)
    prefix = np.zeros(n, dtype=np.int64)
    for i in range(bits):
        b = (r >> (bits - 1 - i)) & 1
        if i <= 16:
            flip = rng.integers(0, 2, 1 << i)[prefix]
        else:  # every prefix below 2^-16 is distinct for n <= 2^16: independent flips
            flip = rng.integers(0, 2, n)
        out |= (b ^ flip) << (bits - 1 - i)
        prefix = (prefix << 1) | b
    return (out + rng.random(n)) / float(1 << bits)


def offsets(kind, n, rng):
    if kind == "ri":
        return owen_radical_inverse(n, rng)
    if kind == "anti":
        a = rng.random((n + 1) // 2)
        o = np.empty(n)
        o[0::2] = a
        o[1::2] = 1.0 - a[: n // 2]
        return o
    return rng.random(n)


def theta_phi_sampler(m, squares, kind):
    """Jittered samples on the sphere (theta = pi u, phi = 2 pi v) along `squares` Hilbert
    squares of m x m cells laid side by side along v."""
    d = np.arange(m * m)
    x, y = hilbert_d2xy(m, d)
    ucell = np.tile(y, squares)                                  # row along u
    vcell = np.concatenate([c * m + x for c in range(squares)])  # column along v
    c0 = np.cos(np.pi * ucell / m)
    c1 = np.cos(np.pi * (ucell + 1) / m)
    cum = np.concatenate([[0.0], np.cumsum(c0 - c1)])
    cum /= cum[-1]

    def sample(n, seed):
        rng = np.random.default_rng([4033, seed, n])
        q = (np.arange(n) + offsets(kind, n, rng)) / n
        c = np.searchsorted(cum, q, side="right") - 1
        ct = c0[c] + (c1[c] - c0[c]) * rng.random(n)
        phi = 2 * np.pi * (vcell[c] + rng.random(n)) / (squares * m)
        st = np.sqrt(np.clip(1 - ct * ct, 0, None))
        return np.stack([st * np.cos(phi), st * np.sin(phi), ct], axis=1)
    return sample


def octahedral(uv):
    """Equal-area octahedral map of [0,1]^2 onto the unit sphere (Clarberg 2008)."""
    u = 2 * uv[:, 0] - 1
    v = 2 * uv[:, 1] - 1
    d = 1 - (np.abs(u) + np.abs(v))
    r = 1 - np.abs(d)
    safe = np.where(r == 0, 1.0, r)
    phi = np.where(r == 0, 1.0, (np.abs(v) - np.abs(u)) / safe + 1) * np.pi / 4
    z = np.sign(d) * (1 - r * r)
    s = r * np.sqrt(np.clip(2 - r * r, 0, None))
    return np.stack([np.sign(u) * np.cos(phi) * s, np.sign(v) * np.sin(phi) * s, z], axis=1)


def octahedral_sampler(m):
    x, y = hilbert_d2xy(m, np.arange(m * m))

    def sample(n, seed):
        rng = np.random.default_rng([4033, seed, n])
        c = np.floor((np.arange(n) + rng.random(n)) / n * (m * m)).astype(np.int64)
        return octahedral(np.stack([(x[c] + rng.random(n)) / m, (y[c] + rng.random(n)) / m], 1))
    return sample


VARIANTS = {
    "curve": lambda: theta_phi_sampler(256, 1, "iid"),
    "wide": lambda: theta_phi_sampler(128, 2, "iid"),
    "octa": lambda: octahedral_sampler(256),
    "ri": lambda: theta_phi_sampler(256, 1, "ri"),
    "anti": lambda: theta_phi_sampler(256, 1, "anti"),
}


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("variants", nargs="*", help="any of %s (default: all)" % ", ".join(VARIANTS))
    ap.add_argument("--seeds", default="1,2,3,4,5,6")
    ap.add_argument("--full", action="store_true", help="sphere_discrepancy.py's default budget")
    args = ap.parse_args()
    args.variants = args.variants or list(VARIANTS)
    unknown = [v for v in args.variants if v not in VARIANTS]
    if unknown:
        raise SystemExit("unknown variant(s) %s; known: %s" % (unknown, ", ".join(VARIANTS)))
    budget = (4000, 4000, 32, 32, 80) if args.full else (1000, 1000, 16, 16, 40)
    measure = sd.SphereMeasure(12345, *budget)
    ns = sd.n_series(64, 6144)
    seeds = [int(s) for s in args.seeds.split(",")]
    slopes = {}
    print("N = %s; seeds %s; budget %s (random, local, keep, props, rounds)" % (
        ",".join(map(str, ns)), seeds, budget))
    for name in args.variants:
        fn = VARIANTS[name]()
        d = np.array([[measure(fn(n, s)) for n in ns] for s in seeds])
        slopes[name] = np.array([sd.slope(ns, row) for row in d])
        mu, se = sd.mean_se(slopes[name])
        line = "%-6s slope %+.3f +- %.3f" % (name, mu, se)
        if name != "curve" and "curve" in slopes:
            dm, dse = sd.mean_se(slopes[name] - slopes["curve"])
            line += "  paired vs curve %+.3f +- %.3f" % (dm, dse)
        scaled = (d * np.array(ns, dtype=float) ** 0.75).mean(0)
        print(line + "  D N^(3/4): " + " ".join("%.2f" % x for x in scaled), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
