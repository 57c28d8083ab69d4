#!/usr/bin/python3
"""Owen's nested uniform scramble against the random linear scramble plus a digital
shift (Matousek 1998), both of Sobol's first two dimensions, through the exact
area-preserving maps of the sphere and the torus (R = 2, r = 1),
f = x^2 + 0.3 y z + exp(z), N = 8192 (issue 36). Shares no code with the sampler:
both scrambles are written here from their definitions (nested: a flip bit per node
of the binary tree of prefixes, from a SplitMix64 hash; linear: a random
lower-triangular binary matrix with unit diagonal times the digits, then a random
shift), and SciPy's `qmc.Sobol(2, scramble=True)` (the linear one) is the third
column; f and the exact means are bench/sobol_integration.py's.

Each scramble's error over seeds 1..S is summarised by its mean |error| +- standard
error, its RMSE, its median and 99th percentile, and the share of seeds above 1e-5.
The two scrambles have the same variance for nets (Owen 2003, "Variance with
alternative scramblings of digital nets"), but not the same distribution: the
linear scramble's error is mostly far smaller with rare large outliers, so a mean
|error| or an RMSE over a few seeds can rank them either way.

    /usr/bin/python3 bench/sobol_scramble_peer.py [--seeds S] [--plane]

--seeds S: seeds 1..S (default 200, about 10 s; 40 s with --plane).
--plane adds smooth integrands on the unit square with closed-form means, periodic
and not, at N = 4096 and 16384.
"""

import sys
from math import erf, pi, sqrt

import numpy as np
from scipy.stats import qmc

from sobol_integration import f_smooth, sphere_exact, torus_exact

SEEDS = range(1, 201)
R, r = 2.0, 1.0
ONE = np.uint64(1)


def mix(z):
    z = (z ^ (z >> np.uint64(30))) * np.uint64(0xbf58476d1ce4e5b9)
    z = (z ^ (z >> np.uint64(27))) * np.uint64(0x94d049bb133111eb)
    return z ^ (z >> np.uint64(31))


def reverse_bits(k):
    k, out = k.astype(np.uint64), np.zeros(len(k), np.uint64)
    for i in range(32):
        out |= ((k >> np.uint64(i)) & ONE) << np.uint64(31 - i)
    return out


def sobol_second(k):
    """Sobol's second dimension: Pascal's triangle mod 2 as generator matrix."""
    k, out, v = k.astype(np.uint64), np.zeros(len(k), np.uint64), np.uint64(0x80000000)
    for i in range(32):
        out ^= np.where((k >> np.uint64(i)) & ONE, v, np.uint64(0))
        v = v ^ (v >> ONE)
    return out


def nested(bits, seed, dim, rng):
    """Owen's nested uniform scramble of 32 digits, then uniform bits below 2^-32."""
    out = np.zeros_like(bits)
    for i in range(32):
        prefix = bits >> np.uint64(32 - i) if i > 0 else np.zeros_like(bits)
        h = mix(np.uint64(seed * 1000003 + dim * 7919 + i * 104729) +
                prefix * np.uint64(0x9e3779b97f4a7c15))
        flip = h >> np.uint64(63)
        out |= (((bits >> np.uint64(31 - i)) & ONE) ^ flip) << np.uint64(31 - i)
    return (out.astype(np.float64) + rng.random(len(bits))) * 2.0**-32


def nested_points(n, seed):
    rng, k = np.random.default_rng(seed), np.arange(n)
    return nested(reverse_bits(k), seed, 0, rng), nested(sobol_second(k), seed, 1, rng)


def linear(bits, rng):
    """The random linear scramble plus a digital shift of 32 digits: digit i of the
    result is digit i plus a random combination of the digits above it, plus a
    random bit; then uniform bits below 2^-32."""
    digit = [(bits >> np.uint64(31 - j)) & ONE for j in range(32)]
    out = np.zeros_like(bits)
    for i in range(32):
        d = digit[i] ^ np.uint64(rng.integers(0, 2))
        for j in np.flatnonzero(rng.integers(0, 2, i)):
            d = d ^ digit[j]
        out |= d << np.uint64(31 - i)
    return (out.astype(np.float64) + rng.random(len(bits))) * 2.0**-32


def linear_points(n, seed):
    rng, k = np.random.default_rng([seed, 2]), np.arange(n)
    return linear(reverse_bits(k), rng), linear(sobol_second(k), rng)


def scipy_points(n, seed):
    p = qmc.Sobol(2, scramble=True, seed=seed).random(n)
    return p[:, 0], p[:, 1]


def on_torus(s, t):
    """The exact area-preserving map: t inverts (R theta + r sin theta) / (2 pi R)."""
    th = 2 * np.pi * t
    for _ in range(60):
        g = (R * th + r * np.sin(th)) / (2 * np.pi * R) - t
        th -= g / ((R + r * np.cos(th)) / (2 * np.pi * R))
    w = R + r * np.cos(th)
    return f_smooth(w * np.cos(2 * np.pi * s), w * np.sin(2 * np.pi * s), r * np.sin(th))


def on_sphere(s, t):
    z, phi = 1 - 2 * t, 2 * np.pi * s
    rho = np.sqrt(np.maximum(0, 1 - z * z))
    return f_smooth(rho * np.cos(phi), rho * np.sin(phi), z)


def bump(c, a=8.0):
    return sqrt(pi / a) / 2 * (erf(sqrt(a) * (1 - c)) - erf(sqrt(a) * (0 - c)))


PLANE = {
    "exp(u+v)": (lambda s, t: np.exp(s + t), (np.e - 1)**2),
    "u^2 v^3": (lambda s, t: s**2 * t**3, 1 / 12),
    "1/(1+u+v)": (lambda s, t: 1 / (1 + s + t), 3 * np.log(3) - 4 * np.log(2)),
    "bump at (0.3, 0.6)": (lambda s, t: np.exp(-8 * ((s - .3)**2 + (t - .6)**2)),
                           bump(.3) * bump(.6)),
    "sin(pi u) cos(pi v/2) + 1": (lambda s, t: np.sin(np.pi * s) * np.cos(np.pi * t / 2) + 1,
                                  (2 / np.pi)**2 + 1),
    "cos(2 pi u)^2 (1+v), periodic in u": (lambda s, t: np.cos(2 * np.pi * s)**2 * (1 + t), 0.75),
}


def errors(points, f, exact, n):
    return np.array([f(*points(n, seed)).mean() - exact for seed in SEEDS])


SCRAMBLES = (("nested", nested_points), ("linear", linear_points), ("scipy", scipy_points))


def summary(e):
    a = np.abs(e)
    return "%.2e +- %.1e  rmse %.2e  median %.1e  q99 %.1e  >1e-5 %3.0f%%" % (
        a.mean(), a.std(ddof=1) / np.sqrt(len(a)), np.sqrt(np.mean(a**2)), np.median(a),
        np.quantile(a, 0.99), 100 * np.mean(a > 1e-5))


def main():
    global SEEDS
    if "--seeds" in sys.argv:
        SEEDS = range(1, int(sys.argv[sys.argv.index("--seeds") + 1]) + 1)
    print("mean |error| +- s.e., seeds 1-%d" % len(SEEDS))
    for name, f, exact in (("torus", on_torus, torus_exact()),
                           ("sphere", on_sphere, sphere_exact())):
        for scramble, points in SCRAMBLES:
            e = errors(points, f, exact, 8192)
            print("%-6s N=8192  %-7s %s" % (name, scramble, summary(e)))
    if "--plane" not in sys.argv:
        return
    for n in (4096, 16384):
        for name, (f, exact) in PLANE.items():
            for scramble, points in SCRAMBLES:
                print("plane N=%5d %-34s %-7s %s" %
                      (n, name, scramble, summary(errors(points, f, exact, n))))


if __name__ == "__main__":
    main()
