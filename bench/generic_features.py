#!/usr/bin/python3
"""Density and area features at generic positions, judged from the CLI's samples (issue 33).

An independent measure: this script shares no code with the sampler. It runs
`sfcsampler sample` (one process at a time), reads the raw samples (u, v, x, y, z
as float64 NPY) and compares them with exact values from closed forms:

  step    the plane (x = u, y = v) with density 1 below a line and 10 above it:
          u < 0.3 (the issue's), u < 1/sqrt(7), v < 1/sqrt(13). Exact share below
          the line C / (C + 10 (1 - C)); the strips [C - 1e-3, C) and [C, C + 1e-3)
          hold 1e-3 / T and 1e-2 / T of the samples (T = C + 10 (1 - C)).
  blowup  the cube-root sheet x = sign(u - c) |u - c|^(1/3), y = v, c = 1/sqrt(5):
          under the area measure x is uniform on [-c^(1/3), (1 - c)^(1/3)] and y on
          [0, 1], so every strip |u - c| in [a, b) holds (b^(1/3) - a^(1/3)) / L
          and the mean of exp(x) + y^2 is (e^B - e^-A) / L + 1/3.
  kink    the double cone x = u cos 2 pi v, y = u sin 2 pi v, z = u, u in [-0.3, 0.7]:
          area element proportional to |u|; strips of |u| and the mean of z
          ((0.7^3 - 0.3^3) / 3 / 0.29) in closed form.
  sweep   the excess share of the u < 0.3 step at N = 2^16 .. 2^22 (the issue's
          "errors that fall with N"), with the fitted slope of log RMS against log N.

Targets are the issue's "What must hold" (steps at N = 4e6, blow-up at 2^18, kink
at 2^20); a verdict at another N uses the same threshold and is marked '*'.

--self-test replaces the CLI by numpy samples drawn from the exact distributions:
  (A) i.i.d. points: every statistic within 4 i.i.d. standard errors of exact;
  (B) points stratified exactly in each marginal (jittered Latin hypercube through
      the inverse CDFs): every target of the issue must PASS;
  (C) the same with the feature displaced by 2e-4 in u: each case must FAIL somewhere.
So a FAIL of the CLI is not the script's.

Usage:
  /usr/bin/python3 bench/generic_features.py [--cli build/client/sfcsampler]
      [--seeds 1,2,3] [--quick] [--cases step,blowup,kink,sweep] [--curve hilbert]
      [--extra-args '--estimator triangle'] [--json out.json] [--self-test]
Exit status: 0 when every verdict passes (self-test: when the self-test holds),
1 when a verdict fails, 2 on an error (also when the CLI binary changed during the run).
"""
import argparse
import json
import math
import os
import re
import shlex
import shutil
import subprocess
import sys
import tempfile
import time
import zlib

import numpy as np

from seed_stats import mean_se

STEP_WIDTH = 1e-3
CONST_RE = re.compile(r"^[0-9.+\-*/() ]*(sqrt\([0-9.+\-*/ ]+\)[0-9.+\-*/() ]*)*$")


def const(text):
    """A constant written the same way in Python and muparser (digits, + - * / ( ), sqrt)."""
    if not CONST_RE.match(text):
        raise ValueError(f"constant {text!r}: only digits, + - * / ( ) and sqrt(...)")
    return float(eval(text, {"__builtins__": {}}, {"sqrt": math.sqrt}))


# ----------------------------------------------------------------------------
# Metrics. Each has an exact value, an i.i.d. standard deviation (for the
# self-test) and a target rule:
#   ("each_abs", tol)       every seed's |error| <= tol
#   ("mean_abs", tol)       |mean error over seeds| <= tol
#   ("count", rel, k)       every seed's |count - exact| <= max(rel exact, k sqrt(exact))
# ----------------------------------------------------------------------------


class Metric:
    def __init__(self, key, label, kind, exact, iid_sd, rule):
        self.key, self.label, self.kind, self.exact, self.iid_sd, self.rule = (
            key, label, kind, exact, iid_sd, rule)

    def error(self, value):
        """share/mean: value - exact; count: (count - exact) / exact."""
        if self.kind == "count":
            return (value - self.exact) / self.exact
        return value - self.exact

    def z(self, value):
        return (value - self.exact) / self.iid_sd if self.iid_sd > 0 else 0.0

    def target_text(self):
        r = self.rule
        if r[0] == "each_abs":
            return f"|err| <= {r[1]:.0e} each seed"
        if r[0] == "mean_abs":
            return f"|mean err| <= {r[1]:.0e}"
        if r[2] > 0:
            return f"max({r[1]:.0%}, {r[2]:g}sqrt) each"
        return f"within {r[1]:.0%} each seed"

    def judge(self, values):
        r = self.rule
        errors = [self.error(v) for v in values]
        if r[0] == "each_abs":
            return all(abs(e) <= r[1] for e in errors)
        if r[0] == "mean_abs":
            return abs(float(np.mean(errors))) <= r[1]
        tol = max(r[1] * self.exact, r[2] * math.sqrt(self.exact))
        return all(abs(v - self.exact) <= tol for v in values)


def count_metric(key, label, n, fraction, rel, k):
    exact = n * fraction
    return Metric(key, label, "count", exact, math.sqrt(exact * (1 - fraction)), ("count", rel, k))


def uniform_pair(n, rng, mode):
    """Two marginal CDF values per point: i.i.d., or a jittered Latin hypercube
    (each marginal stratified into n equal strata, one point each)."""
    if mode == "iid":
        return rng.random(n), rng.random(n)
    s = (rng.permutation(n) + rng.random(n)) / n
    t = (rng.permutation(n) + rng.random(n)) / n
    return s, t


# ----------------------------------------------------------------------------
# Cases
# ----------------------------------------------------------------------------


class Step:
    group = "step"

    def __init__(self, axis, c_text, high=10.0):
        self.axis, self.c_text, self.c, self.high = axis, c_text, const(c_text), high
        self.name = f"step {axis}<{c_text}"
        self.surface = "plane"
        self.density = f"expr:{axis}<{c_text} ? 1 : {high:g}"
        self.total = self.c + high * (1 - self.c)

    def describe(self):
        return (f"plane (x = u, y = v), density {self.density!r}; C = {self.c:.15g}; exact share "
                f"below C = C/(C + {self.high:g}(1-C)) = {self.c / self.total:.12g}")

    def metrics(self, n):
        p = self.c / self.total
        w = STEP_WIDTH
        return [
            Metric("excess", "share below C: excess", "share", p, math.sqrt(p * (1 - p) / n),
                   ("each_abs", 5e-5)),
            count_metric("strip_below", "strip [C-1e-3,C): (count-exact)/exact", n, w / self.total,
                         0.05, 0),
            count_metric("strip_above", "strip [C,C+1e-3): (count-exact)/exact", n,
                         self.high * w / self.total, 0.05, 0),
        ]

    def measure(self, s):
        t = s[self.axis]
        c, w = self.c, STEP_WIDTH
        return {
            "excess": np.count_nonzero(t < c) / t.size,
            "strip_below": np.count_nonzero((t >= c - w) & (t < c)),
            "strip_above": np.count_nonzero((t >= c) & (t < c + w)),
        }

    # Diagnostic (no target): counts in bins beside the step, offsets from C in units of 1e-3.
    profile_edges = (-5, -2, -1, -0.5, 0, 0.5, 1, 2, 5)

    def cdf(self, t):
        t = np.asarray(t, dtype=float)
        return np.where(t < self.c, t, self.c + self.high * (t - self.c)) / self.total

    def profile(self, s, n):
        edges = self.c + 1e-3 * np.array(self.profile_edges)
        counts = np.histogram(s[self.axis], edges)[0]
        return counts, n * np.diff(self.cdf(edges))

    def sanity(self, s):
        return {"max |x-u|": float(np.max(np.abs(s["x"] - s["u"]))),
                "max |y-v|": float(np.max(np.abs(s["y"] - s["v"]))),
                "max |z|": float(np.max(np.abs(s["z"])))}

    def sample(self, n, rng, mode, shift=0.0):
        q, other = uniform_pair(n, rng, mode)
        c = self.c + shift
        tot = c + self.high * (1 - c)
        m = q * tot
        t = np.where(m < c, m, c + (m - c) / self.high)
        u, v = (t, other) if self.axis == "u" else (other, t)
        return {"u": u, "v": v, "x": u.copy(), "y": v.copy(), "z": np.zeros(n)}


class Blowup:
    group = "blowup"
    strips = ((0.0, 1e-4), (1e-4, 1e-3), (1e-3, 1e-2))

    def __init__(self, c_text):
        self.c_text, self.c = c_text, const(c_text)
        c = c_text
        self.name = f"blowup c={c_text}"
        self.surface = (f"expr:x=sign(u-{c})*abs(u-{c})^(1/3);y=v;z=0;"
                        "u0=0;u1=1;v0=0;v1=1")
        self.density = None
        self.lo, self.hi = self.c ** (1 / 3), (1 - self.c) ** (1 / 3)  # x in [-lo, hi]
        self.length = self.lo + self.hi

    def mc_exact(self):
        a, b, L = self.lo, self.hi, self.length
        m1 = (math.exp(b) - math.exp(-a)) / L
        m2 = (math.exp(2 * b) - math.exp(-2 * a)) / (2 * L)
        mean = m1 + 1 / 3
        var = (m2 - m1 * m1) + (1 / 5 - 1 / 9)  # x and y independent
        return mean, math.sqrt(var)

    def describe(self):
        mean, _ = self.mc_exact()
        return (
            f"cube-root sheet at c = {self.c:.15g}: x uniform on [-{self.lo:.6f}, {self.hi:.6f}], "
            f"y uniform; exact mean of exp(x)+y^2 = {mean:.12f}")

    def metrics(self, n):
        out = []
        for a, b in self.strips:
            f = (b ** (1 / 3) - a ** (1 / 3)) / self.length
            for side in ("left", "right", "both"):
                ff = 2 * f if side == "both" else f
                out.append(count_metric(f"strip_{side}_{a:g}_{b:g}",
                                        f"|u-c| in [{a:g},{b:g}) {side}: rel", n, ff, 0.05, 3))
        mean, sd = self.mc_exact()
        out.append(Metric("mc", "mean exp(x)+y^2: bias", "mean", mean, sd / math.sqrt(n),
                          ("mean_abs", 2e-5)))
        return out

    def measure(self, s):
        d = s["u"] - self.c
        ad = np.abs(d)
        r = {}
        for a, b in self.strips:
            inside = (ad >= a) & (ad < b)
            left = np.count_nonzero(inside & (d < 0))
            right = np.count_nonzero(inside & (d >= 0))
            r[f"strip_left_{a:g}_{b:g}"] = left
            r[f"strip_right_{a:g}_{b:g}"] = right
            r[f"strip_both_{a:g}_{b:g}"] = left + right
        r["mc"] = float(np.mean(np.exp(s["x"]) + s["y"] ** 2))
        return r

    def sanity(self, s):
        return {"max |x - cbrt(u-c)|": float(np.max(np.abs(s["x"] - np.cbrt(s["u"] - self.c)))),
                "max |y-v|": float(np.max(np.abs(s["y"] - s["v"]))),
                "max |z|": float(np.max(np.abs(s["z"])))}

    def sample(self, n, rng, mode, shift=0.0):
        q, v = uniform_pair(n, rng, mode)
        c = self.c + shift
        lo, hi = c ** (1 / 3), (1 - c) ** (1 / 3)
        xs = -lo + q * (lo + hi)
        u = c + xs ** 3
        return {"u": u, "v": v, "x": np.cbrt(u - self.c), "y": v.copy(), "z": np.zeros(n)}


class Cone:
    group = "kink"
    strips = ((1e-4, 1e-3), (1e-3, 1e-2))

    def __init__(self, lo=-0.3, hi=0.7):
        self.lo, self.hi = lo, hi
        self.name = f"kink cone u in [{lo:g},{hi:g}]"
        self.surface = (f"expr:x=u*cos(2*_pi*v);y=u*sin(2*_pi*v);z=u;u0={lo:g};u1={hi:g};"
                        "v0=0;v1=1")
        self.density = None
        self.mass = (lo * lo + hi * hi) / 2  # integral of |u|

    def mc_exact(self):
        lo, hi, M = self.lo, self.hi, self.mass
        # E z = int u|u| du / M = (hi^3 - |lo|^3) / 3 / M; E z^2 = (hi^4 + lo^4) / 4 / M
        m1 = (hi ** 3 - abs(lo) ** 3) / 3 / M
        m2 = (hi ** 4 + lo ** 4) / 4 / M
        return m1, math.sqrt(m2 - m1 * m1)

    def describe(self):
        mean, _ = self.mc_exact()
        return (f"double cone, area element ~ |u| on [{self.lo:g}, {self.hi:g}] (apex at unit u = "
                f"{-self.lo / (self.hi - self.lo):g}); exact mean of z = {mean:.12f}")

    def metrics(self, n):
        out = []
        for a, b in self.strips:
            f = (b * b - a * a) / 2 / self.mass
            for side in ("neg", "pos", "both"):
                ff = 2 * f if side == "both" else f
                out.append(count_metric(f"strip_{side}_{a:g}_{b:g}",
                                        f"|u| in ({a:g},{b:g}) {side}: rel", n, ff, 0.05, 3))
        mean, sd = self.mc_exact()
        out.append(Metric("mc", "mean z: bias", "mean", mean, sd / math.sqrt(n),
                          ("mean_abs", 5e-6)))
        return out

    def measure(self, s):
        w = s["z"]  # the native u (z = u exactly)
        aw = np.abs(w)
        r = {}
        for a, b in self.strips:
            inside = (aw > a) & (aw < b)
            neg = np.count_nonzero(inside & (w < 0))
            pos = np.count_nonzero(inside & (w > 0))
            r[f"strip_neg_{a:g}_{b:g}"] = neg
            r[f"strip_pos_{a:g}_{b:g}"] = pos
            r[f"strip_both_{a:g}_{b:g}"] = neg + pos
        r["mc"] = float(np.mean(w))
        return r

    def sanity(self, s):
        w = s["z"]
        return {"max |z - (u0 + u (u1-u0))|":
                float(np.max(np.abs(w - (self.lo + s["u"] * (self.hi - self.lo))))),
                "max |x^2+y^2-z^2|": float(np.max(np.abs(s["x"] ** 2 + s["y"] ** 2 - w * w)))}

    def sample(self, n, rng, mode, shift=0.0):
        q, v = uniform_pair(n, rng, mode)
        a, lo, hi = shift, self.lo, self.hi
        ml, mr = (a - lo) ** 2 / 2, (hi - a) ** 2 / 2
        m = q * (ml + mr)
        w = np.where(m < ml, a - np.sqrt(np.maximum((a - lo) ** 2 - 2 * m, 0)),
                     a + np.sqrt(np.maximum(2 * (m - ml), 0)))
        u = (w - lo) / (hi - lo)
        ang = 2 * np.pi * v
        return {"u": u, "v": v, "x": w * np.cos(ang), "y": w * np.sin(ang), "z": w}


# ----------------------------------------------------------------------------
# Sample sources
# ----------------------------------------------------------------------------


class CliSource:
    def __init__(self, args):
        self.cli, self.curve = args.cli, args.curve
        self.extra = shlex.split(args.extra_args) if args.extra_args else []
        self.tmp = tempfile.mkdtemp(prefix="generic_features_",
                                    dir="/dev/shm" if os.path.isdir("/dev/shm") else None)
        self.versions, self.warnings, self.seconds = set(), {}, 0.0

    def close(self):
        shutil.rmtree(self.tmp, ignore_errors=True)

    def get(self, case, n, seed):
        out = os.path.join(self.tmp, "s.npy")
        cmd = [self.cli, "sample", "--surface", case.surface, "--count", str(n), "--seed",
               str(seed), "--format", "npy", "--columns", "u,v,x,y,z", "-o", out]
        if case.density:
            cmd += ["--density", case.density]
        if self.curve:
            cmd += ["--curve", self.curve]
        cmd += self.extra
        t0 = time.time()
        p = subprocess.run(cmd, capture_output=True, text=True)
        secs = time.time() - t0
        self.seconds += secs
        if p.returncode != 0:
            raise RuntimeError(f"{shlex.join(cmd)} exited {p.returncode}:\n{p.stderr[-2000:]}")
        a = np.load(out)
        os.unlink(out)
        if a.shape[0] != n:
            raise RuntimeError(f"{shlex.join(cmd)} wrote {a.shape[0]} samples, not {n}")
        s = {k: np.ascontiguousarray(a[k], dtype=np.float64) for k in "uvxyz"}
        self.versions.update(re.findall(r"sfcsampler-\d+", p.stderr))
        info = {"seconds": round(secs, 3), "command": shlex.join(cmd)}
        lines = p.stderr.splitlines()
        for i, line in enumerate(lines):
            if line.startswith("tree ") and "leaves" in line:
                info["tree"] = line.strip()
            elif line.startswith("precision:"):
                info["precision"] = line.strip()
            elif re.match(r"(warning|note)\b", line, re.I):
                more = []
                for cont in lines[i + 1:]:
                    if not cont.startswith(" "):
                        break
                    more.append(cont.strip())
                text = line.strip() + (f" [{len(more)} lines, first: {more[0]}]" if more else "")
                self.warnings.setdefault(case.name, set()).add(text)
        return s, info


class ExactSource:
    """numpy samples from the exact distribution (self-test)."""

    def __init__(self, mode, shift=0.0):
        self.mode, self.shift = mode, shift

    def get(self, case, n, seed):
        rng = np.random.default_rng([seed, n, zlib.crc32(case.name.encode())])
        return case.sample(n, rng, self.mode, self.shift), {}


# ----------------------------------------------------------------------------
# Running and reporting
# ----------------------------------------------------------------------------


def file_digest(path):
    import hashlib
    try:
        with open(path, "rb") as f:
            return hashlib.sha256(f.read()).hexdigest()
    except OSError:
        return None


def evaluate(case, n, seeds, source, target_n, log):
    metrics = case.metrics(n)
    values = {m.key: [] for m in metrics}
    runs, sanity, prof = [], {}, []
    prof_exact = None
    for seed in seeds:
        s, info = source.get(case, n, seed)
        r = case.measure(s)
        if hasattr(case, "profile"):
            counts, prof_exact = case.profile(s, n)
            prof.append(counts)
        for k, v in case.sanity(s).items():
            sanity[k] = max(sanity.get(k, 0.0), v)
        for m in metrics:
            values[m.key].append(r[m.key])
        info.update(seed=seed)
        runs.append(info)
        if log:
            log(f"  {case.name} N={n} seed={seed} {info.get('seconds', 0):.1f}s")
        del s
    rows = []
    for m in metrics:
        v = values[m.key]
        errs = [m.error(x) for x in v]
        mu, se = mean_se(errs)
        zs = [m.z(x) for x in v]
        z_mean = (float(np.mean(v)) - m.exact) / (m.iid_sd / math.sqrt(len(v))) if m.iid_sd else 0
        rows.append({
            "key": m.key, "label": m.label, "kind": m.kind, "exact": m.exact,
            "values": [float(x) for x in v], "errors": errs, "mean_error": mu, "se": se,
            "iid_sd": m.iid_sd,
            "iid_sd_error": (m.iid_sd / m.exact if m.kind == "count" else m.iid_sd),
            "z_iid": zs, "z_iid_mean": z_mean, "target": m.target_text(),
            "at_target_n": n == target_n, "pass": bool(m.judge(v)),
        })
    out = {"case": case.name, "group": case.group, "n": n, "surface": case.surface,
           "density": case.density, "description": case.describe(), "rows": rows, "runs": runs,
           "sanity": sanity}
    if prof:
        c = np.array(prof, dtype=float)
        out["profile"] = {"edges_from_c_in_1e-3": list(case.profile_edges),
                          "exact": [float(x) for x in prof_exact],
                          "counts": c.astype(int).tolist(),
                          "rel_error_of_mean": [float(x) for x in c.mean(0) / prof_exact - 1]}
    return out


def fmt_err(kind, x):
    if kind == "count":
        return f"{x * 100:+.2f}%"
    return f"{x:+.2e}"


def print_block(res, out):
    out(f"\n### {res['case']}, N = {res['n']}" + ("" if res["rows"][0]["at_target_n"] else
                                                   "  (* not the issue's N: same threshold)"))
    out(f"    {res['description']}")
    out(f"    {'metric':40s} {'exact':>12s} {'mean err +- SE':>22s} {'i.i.d. SD':>9s} "
        f"{'per seed':>28s}  {'target':28s} verdict")
    for r in res["rows"]:
        ex = f"{r['exact']:.1f}" if r["kind"] == "count" else f"{r['exact']:.8f}"
        se = "" if math.isnan(r["se"]) else fmt_err(r["kind"], r["se"]).lstrip("+")
        ms = f"{fmt_err(r['kind'], r['mean_error'])} +- {se}"
        if r["kind"] == "count":
            seeds = " ".join(f"{int(v)}" for v in r["values"])
            iid = f"{r['iid_sd_error'] * 100:.2f}%"
        else:
            seeds = " ".join(fmt_err(r["kind"], e) for e in r["errors"])
            iid = f"{r['iid_sd_error']:.1e}"
        verdict = ("PASS" if r["pass"] else "FAIL") + ("" if r["at_target_n"] else "*")
        out(f"    {r['label']:40s} {ex:>12s} {ms:>22s} {iid:>9s} {seeds:>28s}  "
            f"{r['target']:28s} {verdict}")
    if "profile" in res:
        p = res["profile"]
        e = p["edges_from_c_in_1e-3"]
        out("    profile beside C (no target; offsets in 1e-3, mean count of seeds vs exact): " +
            ", ".join(f"[{e[i]:g},{e[i + 1]:g}) {p['rel_error_of_mean'][i] * 100:+.1f}%"
                      for i in range(len(e) - 1)))
    trees = sorted({re.sub(r"^tree \S+ ", "", r["tree"]) for r in res["runs"] if "tree" in r})
    if trees:
        out("    CLI tree: " + " | ".join(trees))
    out("    sanity (max over seeds; ~0 says the columns are what the script assumes): " +
        ", ".join(f"{k} = {v:.1e}" + (" (!)" if v > 1e-9 else "")
                  for k, v in res["sanity"].items()))


def sweep(case, ns, seeds, source, log):
    table = []
    p = case.c / case.total
    for n in ns:
        errs, tree = [], ""
        for seed in seeds:
            s, info = source.get(case, n, seed)
            m = re.search(r"(\d+ leaves, depth [\d.]+)", info.get("tree", ""))
            tree = tree or (m.group(1) if m else "")
            errs.append(np.count_nonzero(s[case.axis] < case.c) / n - p)
            if log:
                log(f"  sweep {case.name} N={n} seed={seed} {info.get('seconds', 0):.1f}s")
            del s
        mu, se = mean_se(errs)
        table.append({"n": n, "errors": [float(e) for e in errs], "mean": mu, "se": se,
                      "rms": float(math.sqrt(np.mean(np.square(errs)))),
                      "iid_sd": math.sqrt(p * (1 - p) / n), "tree": tree})
    x = np.log([t["n"] for t in table])
    y = np.log([max(t["rms"], 1e-300) for t in table])
    slope = float(np.polyfit(x, y, 1)[0]) if len(table) >= 2 else float("nan")
    return {"case": case.name, "table": table, "slope": slope,
            "target": "log RMS excess vs log N: slope <= -0.5 (an error that falls with N)",
            "pass": bool(slope <= -0.5)}


def print_sweep(sw, out):
    out(f"\n### N sweep: {sw['case']}, excess share below C")
    out(f"    {'N':>9s} {'mean excess +- SE':>24s} {'RMS':>9s} {'RMS*N':>8s} {'i.i.d. SD':>9s}   "
        f"{'per seed':33s} tree (seed 1)")
    for t in sw["table"]:
        out(f"    {t['n']:>9d} {t['mean']:+.3e} +- {t['se']:.1e} {t['rms']:9.2e} "
            f"{t['rms'] * t['n']:8.1f} {t['iid_sd']:9.1e}   "
            + f"{' '.join(f'{e:+.2e}' for e in t['errors']):33s} " + t["tree"])
    out(f"    fitted slope of log RMS vs log N: {sw['slope']:+.3f}  (target <= -0.5; i.i.d. -0.5, "
        f"a flat bias ~0): {'PASS' if sw['pass'] else 'FAIL'}")


def build_cases(args):
    cases = {}
    cases["step"] = [Step(ax, c) for ax, c in
                     (item.split(":", 1) for item in args.step_positions.split(","))]
    cases["blowup"] = [Blowup(args.blowup_c)]
    cases["kink"] = [Cone()]
    cases["sweep"] = [Step("u", "0.3")]
    return cases


def plan(args):
    if args.quick:
        return {"step": [2 ** 18], "blowup": [2 ** 18], "kink": [2 ** 18],
                "sweep": [2 ** k for k in range(14, 19)]}
    return {"step": [10 ** 6, 4 * 10 ** 6], "blowup": [2 ** 18], "kink": [2 ** 20],
            "sweep": [2 ** k for k in range(16, 23)]}


TARGET_N = {"step": 4 * 10 ** 6, "blowup": 2 ** 18, "kink": 2 ** 20}


def run_all(args, source, out, log):
    cases, ns = build_cases(args), plan(args)
    results, sweeps = [], []
    for group in args.cases:
        if group == "sweep":
            for case in cases["sweep"]:
                sw = sweep(case, ns["sweep"], args.seeds, source, log)
                print_sweep(sw, out)
                sweeps.append(sw)
            continue
        for case in cases[group]:
            for n in ns[group]:
                res = evaluate(case, n, args.seeds, source, TARGET_N[group], log)
                print_block(res, out)
                results.append(res)
    return results, sweeps


def verdicts(results, sweeps, only_target_n=False):
    v = [r["pass"] for res in results for r in res["rows"] if r["at_target_n"] or not only_target_n]
    return v + [s["pass"] for s in sweeps]


def self_test(args, out, log):
    ok = True
    summary = {}
    # (A) i.i.d. exact points: z-scores.
    out("\n## Self-test A: i.i.d. points from the exact distributions (|z| <= 4 against i.i.d. SE)")
    quiet = lambda *_: None
    res_a, sw_a = run_all(args, ExactSource("iid"), quiet, None)
    worst = 0.0
    for res in res_a:
        for r in res["rows"]:
            if r["kind"] == "count" and r["exact"] < 20:  # too few for a normal z
                continue
            zmax = max(max(abs(z) for z in r["z_iid"]), abs(r["z_iid_mean"]))
            worst = max(worst, zmax)
            flag = "ok" if zmax <= 4 else "FAIL"
            if zmax > 4:
                ok = False
            out(f"    {res['case']:22s} N={res['n']:>8d} {r['label']:40s} max|z| {zmax:5.2f} "
                f"{flag}")
    for sw in sw_a:
        for t in sw["table"]:
            zmax = max(abs(e) / t["iid_sd"] for e in t["errors"])
            worst = max(worst, zmax)
            if zmax > 4:
                ok = False
            out(f"    sweep {sw['case']:16s} N={t['n']:>8d} excess share max|z| {zmax:5.2f} "
                f"{'ok' if zmax <= 4 else 'FAIL'}")
    summary["A_worst_z"] = worst
    # (B) exactly stratified marginals: every target passes.
    out("\n## Self-test B: jittered Latin hypercube through the exact inverse CDFs "
        "(every target must PASS)")
    res_b, sw_b = run_all(args, ExactSource("lhs"), out, None)
    b_ok = all(verdicts(res_b, sw_b))
    summary["B_all_pass"] = b_ok
    ok = ok and b_ok
    # (C) the feature displaced by 2e-4: each case fails somewhere.
    out("\n## Self-test C: the same, feature displaced by 2e-4 in u "
        "(each case must FAIL somewhere)")
    res_c, sw_c = run_all(args, ExactSource("lhs", shift=2e-4), quiet, None)
    c_ok = True
    for name in sorted({res["case"] for res in res_c}):
        fails = [f"N={res['n']} {r['label']}" for res in res_c if res["case"] == name
                 for r in res["rows"] if not r["pass"]]
        out(f"    {name:22s} {'detected' if fails else 'NOT DETECTED'}: {len(fails)} failing: "
            + "; ".join(fails[:3]))
        c_ok = c_ok and bool(fails)
    for sw in sw_c:
        out(f"    sweep {sw['case']:16s} slope {sw['slope']:+.3f} "
            f"{'detected' if not sw['pass'] else 'NOT DETECTED'}")
        c_ok = c_ok and not sw["pass"]
    summary["C_all_detected"] = c_ok
    ok = ok and c_ok
    out(f"\nSelf-test: A worst |z| = {worst:.2f} ({'ok' if worst <= 4 else 'FAIL'}), "
        f"B every target {'PASS' if b_ok else 'FAIL'}, C every displacement "
        f"{'detected' if c_ok else 'NOT detected'}: {'OK' if ok else 'FAILED'}")
    return ok, {"A": res_a, "A_sweep": sw_a, "B": res_b, "B_sweep": sw_b, "C": res_c,
                "C_sweep": sw_c, "summary": summary}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter,
                                 epilog=__doc__)
    ap.add_argument("--cli", default="build/client/sfcsampler")
    ap.add_argument("--seeds", default="1,2,3")
    ap.add_argument("--quick", action="store_true", help="smaller N (a smoke run, < 1 min)")
    ap.add_argument("--cases", default="step,blowup,kink,sweep")
    ap.add_argument("--curve", default="hilbert", help="passed as --curve ('' = the CLI's default)")
    ap.add_argument("--extra-args", default="", help="more sfcsampler sample flags, one string")
    ap.add_argument("--step-positions", default="u:0.3,u:1/sqrt(7),v:1/sqrt(13)",
                    help="AXIS:CONSTANT,... (constants as in muparser: digits, + - * / sqrt)")
    ap.add_argument("--blowup-c", default="1/sqrt(5)")
    ap.add_argument("--json", help="write every figure to this file")
    ap.add_argument("--self-test", action="store_true",
                    help="replace the CLI by exact numpy samples and check the script itself")
    args = ap.parse_args()
    args.seeds = [int(s) for s in args.seeds.split(",") if s]
    args.cases = [c for c in args.cases.split(",") if c]
    for c in args.cases:
        if c not in ("step", "blowup", "kink", "sweep"):
            ap.error(f"unknown case {c!r}")
    out = lambda s="": print(s, flush=True)
    log = lambda s: print(s, file=sys.stderr, flush=True)
    t0 = time.time()
    meta = {"seeds": args.seeds, "quick": args.quick, "cases": args.cases,
            "step_positions": args.step_positions, "blowup_c": args.blowup_c,
            "numpy": np.__version__}
    if args.self_test:
        ok, data = self_test(args, out, None)
        meta["seconds"] = round(time.time() - t0, 1)
        if args.json:
            with open(args.json, "w") as f:
                json.dump({"meta": meta, "self_test": data}, f, indent=1, default=float)
        return 0 if ok else 1
    if not os.access(args.cli, os.X_OK):
        print(f"no executable CLI at {args.cli}", file=sys.stderr)
        return 2
    meta.update(cli=os.path.abspath(args.cli), curve=args.curve, extra_args=args.extra_args,
                cli_sha256=file_digest(args.cli))
    source = CliSource(args)
    try:
        out(f"# Generic features (issue 33): curve {args.curve or '(default)'}, seeds "
            f"{','.join(map(str, args.seeds))}{', quick' if args.quick else ''}"
            f"{', extra ' + args.extra_args if args.extra_args else ''}; CLI {args.cli}")
        results, sweeps = run_all(args, source, out, log)
    except (RuntimeError, OSError) as e:
        print(e, file=sys.stderr)
        return 2
    finally:
        source.close()
    changed = file_digest(args.cli) != meta["cli_sha256"]
    meta["cli_changed_during_run"] = changed
    if changed:
        out(f"\nERROR: {args.cli} changed during the run (rebuilt?): the figures mix two binaries")
    meta.update(versions=sorted(source.versions), cli_seconds=round(source.seconds, 1),
                seconds=round(time.time() - t0, 1),
                warnings={k: sorted(v) for k, v in source.warnings.items()})
    if source.warnings:
        out("\nCLI warnings:")
        for k, v in source.warnings.items():
            for line in sorted(v):
                out(f"    {k}: {line}")
    at_target = verdicts(results, sweeps, only_target_n=True)
    allv = verdicts(results, sweeps)
    out(f"\nVersion {', '.join(sorted(source.versions)) or '?'}, CLI sha256 "
        f"{(meta['cli_sha256'] or '?')[:12]}; {sum(allv)}/{len(allv)} checks pass "
        f"({sum(at_target)}/{len(at_target)} at the issue's N); CLI {source.seconds:.0f} s, "
        f"total {time.time() - t0:.0f} s")
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"meta": meta, "results": results, "sweeps": sweeps,
                       "all_pass": all(allv), "all_pass_at_target_n": all(at_target)},
                      f, indent=1, default=float)
    return 2 if changed else 0 if all(allv) else 1


if __name__ == "__main__":
    sys.exit(main())
