#!/usr/bin/python3
"""Independent spherical-triangle discrepancy of sfcsampler's sphere, against references.

Measure (sphere): D(P) = sup over spherical triangles T of |#(P in T)/N - area(T)/(4 pi)|,
estimated from below by
  * R random triangles (vertices uniform on the sphere),
  * L local triangles (vertices scattered around a random centre, size log-uniform),
  * a local search: the K worst triangles of the pool are hill-climbed for `rounds` rounds,
    each vertex perturbed in the tangent plane with a shrinking step; improvements are kept.
Area is exact (Van Oosterom-Strackee: tan(E/2) = |a.(b x c)| / (1 + a.b + b.c + c.a)).
A point p is inside iff s p.(a x b) > 0, s p.(b x c) > 0, s p.(c x a) > 0 with s = sign det(a,b,c).

The pool of triangles and the local search's random proposals depend only on (measure seed, N),
never on the sampler or its seed, so every sampler at a given N is measured on the same
triangles (a paired comparison).

Measure (plane, --surface plane, the unit square): the exact anchored star discrepancy
(sup over [0,x) x [0,y), computed on the critical grid, O(N^2)), and the unanchored box
discrepancy (random boxes + local search, as for the sphere).

Report: least-squares slope of log D against log N over the N series, per sample seed and
mean +- standard error over seeds; and D at the largest N. --profile adds D N^(3/4) at each N
(mean over seeds) and the slope fitted over N >= --fit-from only: every point set's spherical
cap discrepancy is at least of order N^(-3/4) (Beck 1984), and a jittered set's sup carries a
further sqrt(log N), so this shows where a slope is made.

Examples:
  /usr/bin/python3 bench/sphere_discrepancy.py                       # default, Hammersley, iid
  /usr/bin/python3 bench/sphere_discrepancy.py --variant hilbert2="--curve hilbert2" \
      --variant triangle="--estimator triangle"
  /usr/bin/python3 bench/sphere_discrepancy.py --quick
  /usr/bin/python3 bench/sphere_discrepancy.py --seeds 1,2,3,4,5,6 --profile --fit-from 384 \
      --variant sobol="--sequence sobol"
  /usr/bin/python3 bench/sphere_discrepancy.py --self-test
  /usr/bin/python3 bench/sphere_discrepancy.py --pole-caps 100     # counts beside the poles
  /usr/bin/python3 bench/sphere_discrepancy.py --surface plane --variant peano="--curve peano"
"""
import argparse
import json
import math
import os
import shlex
import subprocess
import sys
import tempfile
import time

import numpy as np

from seed_stats import mean_se, slope

DEFAULT_CLI = "build/client/sfcsampler"  # run from the repository root
FOUR_PI = 4.0 * math.pi


# ----------------------------------------------------------------------------- point sets

def radical_inverse2(i):
    i = np.asarray(i, dtype=np.uint64)
    out = np.zeros(i.shape, dtype=np.float64)
    f = 0.5
    while np.any(i):
        out += f * (i & np.uint64(1))
        i = i >> np.uint64(1)
        f *= 0.5
    return out


def hammersley_unit(n):
    i = np.arange(n)
    return np.stack([(i + 0.5) / n, radical_inverse2(i)], axis=1)


def iid_unit(n, seed):
    rng = np.random.default_rng([20240533, seed, n])
    return rng.random((n, 2))


def jittered_unit(n, seed):
    """2D jittered (stratified) on the most nearly square a x b = n grid."""
    a = int(math.isqrt(n))
    while n % a:
        a -= 1
    b = n // a
    rng = np.random.default_rng([777, seed, n])
    i, j = np.meshgrid(np.arange(a), np.arange(b), indexing="ij")
    u = (i.ravel() + rng.random(n)) / a
    v = (j.ravel() + rng.random(n)) / b
    return np.stack([u, v], axis=1)


def unit_to_sphere(st):
    """Exact area-preserving map: z = 1 - 2 s, phi = 2 pi t."""
    z = 1.0 - 2.0 * st[:, 0]
    phi = 2.0 * math.pi * st[:, 1]
    r = np.sqrt(np.clip(1.0 - z * z, 0.0, None))
    return np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=1)


class CliSampler:
    def __init__(self, cli, surface, extra, tmpdir):
        self.cli, self.surface, self.extra, self.tmpdir = cli, surface, extra, tmpdir

    def __call__(self, n, seed):
        path = os.path.join(self.tmpdir, "s.npy")
        cols = "x,y,z" if self.surface == "sphere" else "x,y"
        cmd = [self.cli, "sample", "--surface", self.surface, "-n", str(n), "--seed", str(seed),
               "--format", "npy", "--columns", cols, "-o", path, "-q", "--no-warnings"] + self.extra
        r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        if r.returncode != 0:
            raise RuntimeError("CLI failed (%s): %s" % (" ".join(map(shlex.quote, cmd)), r.stderr))
        a = np.load(path)
        if self.surface == "sphere":
            p = np.stack([a["x"], a["y"], a["z"]], axis=1).astype(np.float64)
            p /= np.linalg.norm(p, axis=1, keepdims=True)
        else:
            p = np.stack([a["x"], a["y"]], axis=1).astype(np.float64)
        if len(p) != n:
            raise RuntimeError("CLI returned %d points, asked %d" % (len(p), n))
        return p


# ----------------------------------------------------------------------------- sphere measure

def normalize(v):
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def random_unit(rng, shape):
    return normalize(rng.standard_normal(tuple(shape) + (3,)))


def tri_area(t):
    """Exact solid angle of spherical triangles t[..., 3 vertices, 3] (Van Oosterom-Strackee)."""
    a, b, c = t[..., 0, :], t[..., 1, :], t[..., 2, :]
    det = np.einsum("...i,...i->...", a, np.cross(b, c))
    den = 1.0 + (a * b).sum(-1) + (b * c).sum(-1) + (c * a).sum(-1)
    return 2.0 * np.arctan2(np.abs(det), den)


def tri_counts(points, t, block=256):
    """Number of points strictly inside each triangle of t[M,3,3]."""
    a, b, c = t[:, 0, :], t[:, 1, :], t[:, 2, :]
    s = np.sign(np.einsum("mi,mi->m", a, np.cross(b, c)))[:, None]
    n1 = np.cross(a, b) * s
    n2 = np.cross(b, c) * s
    n3 = np.cross(c, a) * s
    out = np.empty(len(t), dtype=np.int64)
    pt = points.T.copy()
    for k in range(0, len(t), block):
        sl = slice(k, k + block)
        inside = (n1[sl] @ pt) > 0
        inside &= (n2[sl] @ pt) > 0
        inside &= (n3[sl] @ pt) > 0
        out[sl] = inside.sum(1)
    return out


def sphere_local_search_pool(rng, n, n_random, n_local):
    tri_r = random_unit(rng, (n_random, 3))
    centre = random_unit(rng, (n_local,))
    # Tangent frame at each centre.
    helper = np.where(np.abs(centre[:, :1]) < 0.9, np.array([[1.0, 0, 0]]), np.array([[0, 1.0, 0]]))
    e1 = normalize(np.cross(centre, helper))
    e2 = np.cross(centre, e1)
    lo, hi = math.log(0.7 / math.sqrt(n)), math.log(1.2)
    size = np.exp(rng.uniform(lo, hi, n_local))[:, None, None]
    off = rng.standard_normal((n_local, 3, 2)) * size
    tri_l = normalize(centre[:, None, :] + off[..., :1] * e1[:, None, :] +
                      off[..., 1:] * e2[:, None, :])
    return np.concatenate([tri_r, tri_l], axis=0)


def perturb_sphere(rng, t, scale=None):
    """Move one vertex (or, with probability 1/4, all three) by a tangent Gaussian step whose
    size is log-uniform in [0.002, 0.3] times the triangle's longest chord (multi-scale)."""
    edge = np.linalg.norm(t - np.roll(t, 1, axis=1), axis=-1).max(-1)  # chord length
    sc = np.exp(rng.uniform(math.log(0.002), math.log(0.3), len(t)))
    step = (sc * np.maximum(edge, 1e-3))[:, None, None]
    noise = rng.standard_normal(t.shape) * step
    v = rng.integers(0, 4, len(t))
    mask = (np.arange(3)[None, :] == v[:, None]) | (v[:, None] == 3)
    return normalize(t + noise * mask[:, :, None])


class SphereMeasure:
    """Triangles fixed per (measure seed, N); the local search's randomness too."""

    def __init__(self, seed, n_random, n_local, keep, props, rounds):
        self.seed, self.n_random, self.n_local = seed, n_random, n_local
        self.keep, self.props, self.rounds = keep, props, rounds
        self._pool = {}

    def pool(self, n):
        if n not in self._pool:
            rng = np.random.default_rng([self.seed, n, 0])
            t = sphere_local_search_pool(rng, n, self.n_random, self.n_local)
            self._pool[n] = (t, tri_area(t) / FOUR_PI)
        return self._pool[n]

    def __call__(self, points):
        n = len(points)
        t, area = self.pool(n)
        d = np.abs(tri_counts(points, t) / n - area)
        best_i = np.argsort(-d)[: self.keep]
        best_t, best_d = t[best_i].copy(), d[best_i].copy()
        rng = np.random.default_rng([self.seed, n, 1])
        for _ in range(self.rounds):
            cand = perturb_sphere(rng, np.repeat(best_t, self.props, axis=0))
            cd = np.abs(tri_counts(points, cand) / n - tri_area(cand) / FOUR_PI)
            cd = cd.reshape(self.keep, self.props)
            j = cd.argmax(1)
            better = cd[np.arange(self.keep), j] > best_d
            if np.any(better):
                idx = np.nonzero(better)[0]
                best_t[idx] = cand.reshape(self.keep, self.props, 3, 3)[idx, j[idx]]
                best_d[idx] = cd[idx, j[idx]]
        return float(max(d.max(), best_d.max()))


# ----------------------------------------------------------------------------- plane measures

def star_discrepancy_exact(p):
    """Exact anchored star discrepancy of points in [0,1)^2 (sup over [0,x) x [0,y) / closed)."""
    n = len(p)
    ox = np.argsort(p[:, 0], kind="stable")
    xs = np.append(p[ox, 0], 1.0)
    yr = np.empty(n, dtype=np.int64)
    yr[np.argsort(p[:, 1], kind="stable")] = np.arange(n)
    ys = np.append(np.sort(p[:, 1]), 1.0)
    yrank_by_x = yr[ox]  # y-rank of the i-th point in x order
    # C[i, j] = #points with x-rank < i and y-rank < j, for i, j in 0..n.
    best = 0.0
    row = np.zeros(n + 1, dtype=np.int64)  # C[i, :]
    block = 256
    for i0 in range(0, n + 1, block):
        i1 = min(n + 1, i0 + block)
        # Rows i0..i1-1: row i adds the points with x-rank < i.
        one = np.zeros((i1 - i0, n + 1), dtype=np.int32)
        # Point with x-rank k contributes to rows i > k: row i = i0 + r covers points k < i.
        ks = np.arange(max(i0 - 1, 0), i1 - 1)
        if i0 == 0:
            rowidx = ks + 1 - i0
        else:
            rowidx = ks - (i0 - 1)
        if len(ks):
            one[rowidx, yrank_by_x[ks] + 1] = 1  # y-rank < j  <=>  j >= rank + 1
        inc = np.cumsum(np.cumsum(one, axis=1), axis=0)
        C = row[None, :] + inc
        row = C[-1].copy()
        X = xs[i0:i1][:, None]
        # open boxes [0, xs[i]) x [0, ys[j]):  area - C[i, j] / n
        best = max(best, float((X * ys[None, :] - C / n).max()))
        # closed boxes [0, xs[i]] x [0, ys[j]] (points only, i, j < n): C[i+1, j+1] / n - area
        ii = np.arange(i0, i1)
        ok = ii < n
        if np.any(ok):
            # C[i+1, j+1] = C[i, j+1] + [point i has y-rank <= j]
            Cn = C[ok][:, 1:] + (np.arange(n)[None, :] >= yrank_by_x[ii[ok]][:, None])
            best = max(best, float((Cn / n - X[ok] * ys[None, :n]).max()))
    return best


def box_counts(p, boxes, block=512):
    out = np.empty(len(boxes), dtype=np.int64)
    x, y = p[:, 0][None, :], p[:, 1][None, :]
    for k in range(0, len(boxes), block):
        b = boxes[k:k + block]
        inside = (x > b[:, 0:1]) & (x < b[:, 1:2]) & (y > b[:, 2:3]) & (y < b[:, 3:4])
        out[k:k + block] = inside.sum(1)
    return out


def box_area(b):
    return (b[:, 1] - b[:, 0]) * (b[:, 3] - b[:, 2])


def sort_box(b):
    x = np.sort(np.clip(b[:, 0:2], 0, 1), axis=1)
    y = np.sort(np.clip(b[:, 2:4], 0, 1), axis=1)
    return np.concatenate([x, y], axis=1)


class BoxMeasure:
    def __init__(self, seed, n_random, n_local, keep, props, rounds):
        self.seed, self.n_random, self.n_local = seed, n_random, n_local
        self.keep, self.props, self.rounds = keep, props, rounds
        self._pool = {}

    def pool(self, n):
        if n not in self._pool:
            rng = np.random.default_rng([self.seed, n, 0])
            b1 = sort_box(rng.random((self.n_random, 4)))
            c = rng.random((self.n_local, 2))
            s = np.exp(rng.uniform(math.log(0.7 / math.sqrt(n)), math.log(0.7), (self.n_local, 2)))
            b2 = sort_box(np.stack([c[:, 0] - s[:, 0] / 2, c[:, 0] + s[:, 0] / 2,
                                    c[:, 1] - s[:, 1] / 2, c[:, 1] + s[:, 1] / 2], axis=1))
            b = np.concatenate([b1, b2])
            self._pool[n] = (b, box_area(b))
        return self._pool[n]

    def __call__(self, p):
        n = len(p)
        b, area = self.pool(n)
        d = np.abs(box_counts(p, b) / n - area)
        bi = np.argsort(-d)[: self.keep]
        bb, bd = b[bi].copy(), d[bi].copy()
        rng = np.random.default_rng([self.seed, n, 1])
        for r in range(self.rounds):
            cand = np.repeat(bb, self.props, axis=0)
            w = np.maximum(
                np.stack([cand[:, 1] - cand[:, 0]] * 2 + [cand[:, 3] - cand[:, 2]] * 2, 1), 1e-3)
            scale = np.exp(rng.uniform(math.log(0.002), math.log(0.3), (len(cand), 1)))
            mask = rng.random(cand.shape) < 0.5
            cand = sort_box(cand + rng.standard_normal(cand.shape) * w * scale * mask)
            cd = np.abs(box_counts(p, cand) / n - box_area(cand)).reshape(self.keep, self.props)
            j = cd.argmax(1)
            better = cd[np.arange(self.keep), j] > bd
            idx = np.nonzero(better)[0]
            bb[idx] = cand.reshape(self.keep, self.props, 4)[idx, j[idx]]
            bd[idx] = cd[idx, j[idx]]
        return float(max(d.max(), bd.max()))


# ----------------------------------------------------------------------------- driver

def n_series(n_min, n_max):
    """64, 96, 128, 192, ... (factors 1.5 and 4/3 alternating) up to n_max."""
    out, n = [], n_min
    while n <= n_max:
        out.append(n)
        m = n * 3 // 2
        if m <= n_max:
            out.append(m)
        n *= 2
    return sorted(set(out))


def build_samplers(args, tmpdir):
    sph = args.surface == "sphere"
    conv = unit_to_sphere if sph else (lambda st: st)
    s = []
    if not args.no_default:
        s.append(("default", CliSampler(args.cli, args.surface, [], tmpdir)))
    for spec in args.variant:
        if "=" not in spec:
            raise SystemExit("--variant wants NAME=ARGS, got %r" % spec)
        name, extra = spec.split("=", 1)
        s.append((name, CliSampler(args.cli, args.surface, shlex.split(extra), tmpdir)))
    if not args.no_reference:
        s.append(("hammersley", lambda n, seed: conv(hammersley_unit(n))))
        if not sph:
            s.append(("jittered2d", lambda n, seed: conv(jittered_unit(n, seed))))
        s.append(("iid", lambda n, seed: conv(iid_unit(n, seed))))
    return s


def run(args):
    ns = n_series(args.n_min, args.n_max)
    seeds = [int(x) for x in args.seeds.split(",")]
    if args.surface == "sphere":
        measures = {"tri": SphereMeasure(args.measure_seed, args.random, args.local, args.keep,
                                         args.props, args.rounds)}
    else:
        measures = {"star": None,
                    "box": BoxMeasure(args.measure_seed, args.random, args.local, args.keep,
                                      args.props, args.rounds)}
    t0 = time.time()
    results = {}
    with tempfile.TemporaryDirectory() as tmpdir:
        samplers = build_samplers(args, tmpdir)
        for name, fn in samplers:
            results[name] = {m: {} for m in measures}
            for seed in seeds:
                for m in measures:
                    results[name][m][seed] = []
                for n in ns:
                    p = fn(n, seed)
                    for m, meas in measures.items():
                        d = star_discrepancy_exact(p) if m == "star" else meas(p)
                        results[name][m][seed].append(d)
            if args.verbose:
                print("  [%s done, %.0f s]" % (name, time.time() - t0), file=sys.stderr)
    report(args, ns, seeds, results)
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"ns": ns, "seeds": seeds, "args": vars(args), "results":
                       {k: {m: {str(s): d for s, d in v.items()} for m, v in mv.items()}
                        for k, mv in results.items()}}, f, indent=1)
    print("(%.0f s)" % (time.time() - t0))
    return ns, results


def summarise(ns, per_seed):
    sl = [slope(ns, d) for d in per_seed.values()]
    m, se = mean_se(sl)
    dl = [d[-1] for d in per_seed.values()]
    return sl, m, se, float(np.mean(dl))


def report(args, ns, seeds, results):
    print(
        "surface %s; N = %s; seeds %s; measure seed %d; %d random + %d local, search %d x %d x %d" %
        (args.surface, ",".join(map(str, ns)), seeds, args.measure_seed, args.random, args.local,
         args.keep, args.props, args.rounds))
    for m in next(iter(results.values())):
        label = {"tri": "spherical triangles", "star": "anchored star (exact)",
                 "box": "unanchored boxes (search)"}[m]
        print("\nmeasure: %s" % label)
        base = results.get("default", {}).get(m)
        print("%-14s %-22s %-16s %-12s %s" % ("sampler", "slope per seed", "mean +- SE",
                                              "D(N=%d)" % ns[-1], "paired diff vs default"))
        for name, mv in results.items():
            sl, mu, se, dl = summarise(ns, mv[m])
            diff = ""
            if base is not None and name != "default":
                bs = [slope(ns, base[s]) for s in seeds]
                dm, dse = mean_se(np.array(sl) - np.array(bs))
                diff = "%+.3f +- %.3f" % (dm, dse)
            print("%-14s %-22s %+.3f +- %.3f   %.5f      %s" % (
                name, " ".join("%+.3f" % x for x in sl), mu, se, dl, diff))
        if args.profile:
            profile(args, ns, results, m)


def profile(args, ns, results, m):
    """D N^(3/4) at each N (mean over seeds) and the slope over N >= args.fit_from."""
    tail = [i for i, n in enumerate(ns) if n >= args.fit_from]
    if len(tail) < 2:
        raise SystemExit("--fit-from %d leaves fewer than 2 N" % args.fit_from)
    print("\nD N^(3/4), mean over seeds, at N = %s" % ",".join(map(str, ns)))
    for name, mv in results.items():
        d = np.array(list(mv[m].values()))
        scaled = (d * np.array(ns, dtype=float) ** 0.75).mean(0)
        tail_sl = [slope([ns[i] for i in tail], row[tail]) for row in d]
        mu, se = mean_se(tail_sl)
        print("%-14s %s   slope N >= %d: %+.3f +- %.3f" % (
            name, " ".join("%.2f" % x for x in scaled), args.fit_from, mu, se))


def self_test(args):
    """iid should give slope ~ -0.5; Hammersley clearly steeper; the area formula exact."""
    ok = True
    # Area checks: octant triangle = 4 pi / 8; Monte Carlo for a random triangle.
    octant = np.eye(3)[None]
    a = tri_area(octant)[0]
    print("octant area %.12f (exact %.12f)" % (a, math.pi / 2))
    ok &= abs(a - math.pi / 2) < 1e-12
    rng = np.random.default_rng(5)
    t = random_unit(rng, (20, 3))
    mc = random_unit(rng, (400000,))
    frac = tri_counts(mc, t) / len(mc)
    err = np.abs(frac - tri_area(t) / FOUR_PI).max()
    print("area vs Monte Carlo (4e5 points, 20 triangles): max |diff| %.5f" % err)
    ok &= err < 0.003
    # Star discrepancy exact vs brute force on a small set.
    p = rng.random((40, 2))
    bf = 0.0
    gx, gy = np.append(p[:, 0], 1.0), np.append(p[:, 1], 1.0)
    for x in gx:
        for y in gy:
            o = np.sum((p[:, 0] < x) & (p[:, 1] < y)) / 40
            c = np.sum((p[:, 0] <= x) & (p[:, 1] <= y)) / 40
            bf = max(bf, x * y - o, c - x * y)
    ex = star_discrepancy_exact(p)
    print("star discrepancy exact %.6f, brute force %.6f" % (ex, bf))
    ok &= abs(ex - bf) < 1e-12
    # Slopes.
    args.no_default, args.variant, args.seeds = True, [], args.seeds or "1,2,3"
    ns, res = run(args)
    key = "tri" if args.surface == "sphere" else "star"
    _, si, _, _ = summarise(ns, res["iid"][key])
    _, sh, _, _ = summarise(ns, res["hammersley"][key])
    print("self-test: iid slope %+.3f (want -0.5 +- 0.12), hammersley %+.3f (want < iid - 0.15)"
          % (si, sh))
    ok &= abs(si + 0.5) < 0.12 and sh < si - 0.15
    print("SELF-TEST", "PASS" if ok else "FAIL")
    return 0 if ok else 1


def pole_caps(args):
    """Samples in the caps z > 1 - 2 e / N and z < -1 + 2 e / N (e samples expected in each),
    mean of the two poles minus e, over seeds 1..args.pole_caps, at N = args.n_max."""
    n = args.n_max
    expect = [0.5, 1, 2, 4, 8, 16, 32, 64, 256]
    with tempfile.TemporaryDirectory() as tmpdir:
        fn = CliSampler(args.cli, "sphere", [], tmpdir)
        dev = np.array([[(np.sum(p[:, 2] > 1 - 2 * e / n) + np.sum(p[:, 2] < -1 + 2 * e / n)) / 2
                         - e for e in expect] for p in (fn(n, s)
                                                        for s in range(1, args.pole_caps + 1))])
    print("N = %d, seeds 1-%d: samples in a cap about a pole (mean of both) minus expected" %
          (n, args.pole_caps))
    for e, col in zip(expect, dev.T):
        mu, se = mean_se(col)
        print("expected %6.1f: %+.3f +- %.3f (rms %.3f)" % (e, mu, se, math.sqrt(np.mean(col**2))))
    return 0


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cli", default=DEFAULT_CLI)
    ap.add_argument("--surface", default="sphere", choices=["sphere", "plane"])
    ap.add_argument("--variant", action="append", default=[], metavar="NAME=ARGS",
                    help='extra CLI sampler, e.g. hilbert2="--curve hilbert2" (repeatable)')
    ap.add_argument("--seeds", default="1,2,3")
    ap.add_argument("--measure-seed", type=int, default=12345)
    ap.add_argument("--n-min", type=int, default=64)
    ap.add_argument("--n-max", type=int, default=6144)
    ap.add_argument("--random", type=int, default=4000, help="random triangles (boxes)")
    ap.add_argument("--local", type=int, default=4000, help="local triangles (boxes)")
    ap.add_argument("--keep", type=int, default=32, help="worst triangles kept for local search")
    ap.add_argument("--props", type=int, default=32, help="proposals per kept triangle per round")
    ap.add_argument("--rounds", type=int, default=80, help="local-search rounds")
    ap.add_argument("--no-default", action="store_true", help="omit the CLI with default options")
    ap.add_argument("--no-reference", action="store_true", help="omit Hammersley / iid")
    ap.add_argument("--quick", action="store_true", help="fewer N, triangles and rounds (~1 min)")
    ap.add_argument("--self-test", action="store_true")
    ap.add_argument("--pole-caps", type=int, default=0, metavar="SEEDS",
                    help="only count the samples beside the poles at N = --n-max, seeds 1..SEEDS")
    ap.add_argument("--json", help="also write the raw discrepancies here")
    ap.add_argument("--profile", action="store_true",
                    help="also print D N^(3/4) at each N and the slope over N >= --fit-from")
    ap.add_argument("--fit-from", type=int, default=384, help="smallest N of --profile's slope")
    ap.add_argument("-v", "--verbose", action="store_true")
    args = ap.parse_args()
    if args.quick:
        args.random, args.local, args.keep, args.props, args.rounds = 1000, 1000, 16, 16, 40
    if args.self_test:
        return self_test(args)
    if args.pole_caps:
        return pole_caps(args)
    if (args.surface == "sphere" and not os.path.exists(args.cli)
            and (not args.no_default or args.variant)):
        raise SystemExit("no CLI at %s (use --cli)" % args.cli)
    run(args)
    return 0


if __name__ == "__main__":
    sys.exit(main())
