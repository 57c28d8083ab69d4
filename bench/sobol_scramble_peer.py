#!/usr/bin/python3
"""Owen's nested uniform scramble against SciPy's scrambled Sobol (random linear
scramble plus digital shift), both through the exact area-preserving maps of
the sphere and the torus (R = 2, r = 1), f = x^2 + 0.3 y z + exp(z), N = 8192,
seeds 1-20 (issue 36). Shares no code with the sampler: the nested scramble is
written here from its definition (a flip bit per node of the binary tree of
prefixes, from a SplitMix64 hash); f and the exact means are
bench/sobol_integration.py's.

    /usr/bin/python3 bench/sobol_scramble_peer.py [--plane]

--plane adds smooth integrands on the unit square with closed-form means, periodic
and not, at N = 4096 and 16384 (RMSE over seeds 1-20).
"""

import sys
from math import erf, pi, sqrt

import numpy as np
from scipy.stats import qmc

from sobol_integration import f_smooth, sphere_exact, torus_exact

SEEDS = range(1, 21)
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


def main():
    se = np.sqrt(len(SEEDS))
    for name, f, exact in (("torus", on_torus, torus_exact()),
                           ("sphere", on_sphere, sphere_exact())):
        eo, el = (np.abs(errors(p, f, exact, 8192)) for p in (nested_points, scipy_points))
        print("%s owen mean|err| %.2e +- %.1e   scipy LMS+shift %.2e +- %.1e  (20 seeds)" %
              (name, eo.mean(), eo.std() / se, el.mean(), el.std() / se))
    if "--plane" not in sys.argv:
        return
    for n in (4096, 16384):
        for name, (f, exact) in PLANE.items():
            eo, el = (errors(p, f, exact, n) for p in (nested_points, scipy_points))
            print("plane N=%6d %-36s RMSE nested %.2e  LMS+shift %.2e" %
                  (n, name, np.sqrt(np.mean(eo**2)), np.sqrt(np.mean(el**2))))


if __name__ == "__main__":
    main()
