#!/usr/bin/env python3
"""Monte Carlo integration over a surface: the error against N for i.i.d.
points and for sfcsampler's jittered space-filling-curve samples.

The integral of f(x, y, z) = exp(z) over the unit sphere is known exactly:
  I = 2 pi * integral_{-1}^{1} e^t dt = 2 pi (e - 1/e)
(on the unit sphere dA = 2 pi dt in t = z, by Archimedes' hat-box theorem).
With N points spread in proportion to area, I ~ 4 pi * mean(f). For each N
the RMS error over several seeds is compared for
  - i.i.d. uniform points (normalised Gaussian vectors, NumPy), and
  - sfcsampler.sample(surface="sphere", count=N, seed=s) (jittered, Hilbert),
and the slopes of log(error) against log(N) are printed and drawn as a
log-log plot: i.i.d. error falls as N^-1/2, ours faster, which is the reason
the method exists (paper Sect. 4).

  PYTHONPATH=build/python python3 examples/monte_carlo.py --out mc.png
  PYTHONPATH=build/python python3 examples/monte_carlo.py --server 127.0.0.1:50051
"""

import argparse
import math
import sys

import numpy as np

import sfcsampler

EXACT = 2 * math.pi * (math.e - 1 / math.e)
AREA = 4 * math.pi


def f(x, y, z):
    return np.exp(z)


def iid_estimate(n, seed):
    g = np.random.default_rng(seed).standard_normal((n, 3))
    g /= np.linalg.norm(g, axis=1, keepdims=True)
    return AREA * f(g[:, 0], g[:, 1], g[:, 2]).mean()


def slope(ns, errors):
    """Least-squares slope of log(error) against log(N)."""
    return float(np.polyfit(np.log(ns), np.log(errors), 1)[0])


def run(min_exp, max_exp, seeds, sample):
    ns = [2 ** k for k in range(min_exp, max_exp + 1)]
    rows = []
    for n in ns:
        sets = (sample(surface="sphere", count=n, seed=seed) for seed in range(1, seeds + 1))
        ours = [AREA * f(s.x, s.y, s.z).mean() for s in sets]
        iid = [iid_estimate(n, seed) for seed in range(1, seeds + 1)]
        rms = lambda estimates: math.sqrt(np.mean((np.array(estimates) - EXACT) ** 2))
        rows.append((n, rms(iid), rms(ours)))
    return rows


def plot(rows, path, slopes):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    ns = [r[0] for r in rows]
    fig, ax = plt.subplots(figsize=(6, 4.5), dpi=120)
    ax.loglog(ns, [r[1] for r in rows], "o-", label=f"i.i.d. uniform (slope {slopes[0]:.2f})")
    ax.loglog(ns, [r[2] for r in rows], "s-",
              label=f"sfcsampler jittered Hilbert (slope {slopes[1]:.2f})")
    ref = rows[0][1] * (np.array(ns) / ns[0]) ** -0.5
    ax.loglog(ns, ref, ":", color="gray", label="N^-1/2")
    ax.set_xlabel("N (samples)")
    ax.set_ylabel("RMS error of the integral")
    ax.set_title("Monte Carlo integral of exp(z) over the unit sphere")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(path)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--min-exp", type=int, default=6, help="smallest N = 2^min_exp")
    parser.add_argument("--max-exp", type=int, default=18, help="largest N = 2^max_exp")
    parser.add_argument("--seeds", type=int, default=16, help="repetitions per N (RMS over them)")
    parser.add_argument("--out", default="monte_carlo.png", help="the log-log plot (PNG)")
    parser.add_argument("--server",
                        help="HOST:PORT: sample through sfcsampler.Client instead of in-process")
    args = parser.parse_args(argv)

    client = sfcsampler.Client(args.server) if args.server else None
    sample = client.sample if client else sfcsampler.Sampler(max_trees=2).sample
    rows = run(args.min_exp, args.max_exp, args.seeds, sample)
    ns = [r[0] for r in rows]
    slopes = (slope(ns, [r[1] for r in rows]), slope(ns, [r[2] for r in rows]))
    print(f"exact integral 2 pi (e - 1/e) = {EXACT:.12f}; RMS error over {args.seeds} seeds")
    print(f"{'N':>9} {'i.i.d.':>12} {'sfcsampler':>12}")
    for n, iid, ours in rows:
        print(f"{n:>9} {iid:>12.3e} {ours:>12.3e}")
    print(f"slope of log(error) vs log(N): i.i.d. {slopes[0]:.3f}, sfcsampler {slopes[1]:.3f}")
    plot(rows, args.out, slopes)
    print(f"wrote {args.out}")
    if client:
        client.close()
    return slopes


if __name__ == "__main__":
    main(sys.argv[1:])
