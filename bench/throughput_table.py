#!/usr/bin/python3
"""Issue 20's throughput table, every row in one run, each next to its peer.

    PYTHONPATH=build/python /usr/bin/python3 bench/throughput_table.py [BUILD_DIR=build] [--quick]

Rows (the peer in brackets; ratios are taken round by round, A B A B, so a
noisy machine's load hits both sides alike):
 1. 4 M sphere samples from a cached tree, in process, one thread, columns
    u, v, x, y, z float64 (the Python package), against numpy computing the
    same five columns for i.i.d. points on the sphere. Also scipy's scrambled
    Sobol points mapped to the sphere, the other low-discrepancy peer.
 2. Tree build plus 10^6 sphere samples, one core (bench/core_benchmark).
 3. Cold CLI, 4 M sphere samples to a binary PLY file, against a numpy
    script writing the same file; 5 paired runs.
 4. float32 stream over loopback against a raw bytes stream of the same size,
    and 5. a cache hit against a cold request (eight, curvature density,
    10^6): both from bench/stream_benchmark, whose process has the server's
    malloc settings (both sides' buffers reuse resident pages; before branch stream-speed
    it had glibc's defaults, under which the raw bytes ran about half as fast).
 6. STEP box with a fillet and a hole, 10^6 cold, against the built-in
    sphere (bench/model_benchmark).
 7. Mesh, 10^6 cold on the 81 920-triangle icosphere, against Open3D's
    sample_points_uniformly (bench/mesh_vs_open3d.py).
 8. Warm in-process calls whose results are dropped: the kernel's share of
    the CPU time, with and without the Sampler's output pool.
 9. A new interpreter's import plus its first 1 000 in-process samples.
10. Samples a second from a built tree, one core, per surface of
    core_benchmark's BM_SampleSurface, and the cost at N = 2^23 + 1 against 10^6.
11. Two threads against one (core_benchmark's BM_SampleFromBuiltTreeThreads).
12. sample_many of 1 000 small meshes against a loop over Open3D
    (bench/many_meshes.py).
--quick runs rows 1-3 and 8-11 only. The CPU's vector path (SSE2/AVX/AVX2/AVX-512F) is
printed first; the bytes never depend on it.
"""

import os
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

BUILD = next((a for a in sys.argv[1:] if not a.startswith("--")), "build")
QUICK = "--quick" in sys.argv
HERE = os.path.dirname(os.path.abspath(__file__))
ROUNDS = 5


def run(cmd, **kw):
    return subprocess.run(cmd, check=True, capture_output=True, text=True, **kw).stdout


def timed(fn):
    t = time.perf_counter()
    fn()
    return time.perf_counter() - t


def paired(a, b, rounds=ROUNDS):
    """Times of a and b, alternating; returns (times_a, times_b)."""
    ta, tb = [], []
    for _ in range(rounds):
        ta.append(timed(a))
        tb.append(timed(b))
    return ta, tb


def numpy_sphere(n, rng):
    """u, v, x, y, z float64 for n i.i.d. uniform points on the unit sphere."""
    u = rng.random(n)
    v = rng.random(n)
    z = 1 - 2 * u
    r = np.sqrt(1 - z * z)
    phi = 2 * np.pi * v
    return u, v, r * np.cos(phi), r * np.sin(phi), z


def row_python(n=4_000_000):
    import sfcsampler
    sampler = sfcsampler.Sampler(max_trees=4, threads=1)
    request = dict(surface="sphere", count=n, seed=1)
    sampler.sample(**request)  # builds and keeps the tree
    rng = np.random.default_rng(1)
    ours, theirs = paired(lambda: sampler.sample(**request), lambda: numpy_sphere(n, rng))
    ratios = [b / a for a, b in zip(ours, theirs)]
    rows = [(f"1. {n / 1e6:.0f} M sphere samples, cached tree, Python, 1 thread, u v x y z float64",
             f"{statistics.median(ours):.3f} s ({n / statistics.median(ours) / 1e6:.1f} M/s)",
             f"numpy i.i.d. {statistics.median(theirs):.3f} s",
             f"speed ratio {statistics.median(ratios):.2f} "
             f"(rounds {min(ratios):.2f}-{max(ratios):.2f})")]
    try:
        from scipy.stats import qmc
        sobol = qmc.Sobol(d=2, scramble=True, seed=1)
        m = 1 << (n - 1).bit_length()
        t = timed(lambda: sobol.random(m))
        rows.append(("   scipy scrambled Sobol, the 2D points alone (2^22)", "", f"{t:.3f} s",
                     f"{m / t / 1e6:.1f} M points/s before mapping"))
    except ImportError:
        pass
    return rows


def kernel_share(fn, rounds=ROUNDS):
    """Kernel (system) time as a share of fn's CPU time over `rounds` calls."""
    import resource
    r0 = resource.getrusage(resource.RUSAGE_SELF)
    for _ in range(rounds):
        fn()
    r1 = resource.getrusage(resource.RUSAGE_SELF)
    user, system = r1.ru_utime - r0.ru_utime, r1.ru_stime - r0.ru_stime
    return system / (user + system)


def row_warm_kernel(n=4_000_000):
    """Warm calls whose results are dropped at once: with the output pool their
    arrays refill the last call's memory; without, the kernel faults in and zeroes
    fresh pages each time."""
    import sfcsampler
    request = dict(surface="sphere", count=n, seed=1)
    pooled = sfcsampler.Sampler(max_trees=1, threads=1)
    unpooled = sfcsampler.Sampler(max_trees=1, threads=1, output_pool_bytes=0)
    shares = {"pooled": [], "unpooled": []}
    for sampler in (pooled, unpooled):
        sampler.sample(**request)
    for _ in range(3):  # alternating
        for name, sampler in (("pooled", pooled), ("unpooled", unpooled)):
            shares[name].append(kernel_share(lambda: sampler.sample(**request), rounds=3))
    p, u = shares["pooled"], shares["unpooled"]
    return [(f"8. warm in-process calls, {n / 1e6:.0f} M sphere samples each, results dropped: "
             "kernel share of CPU time",
             f"{statistics.median(p):.1%} ({min(p):.1%}-{max(p):.1%})",
             f"without the output pool {statistics.median(u):.1%}", "target under 5%")]


def row_first_sample():
    """A new interpreter: import sfcsampler and take 1 000 sphere samples."""
    code = ("import time; t = time.perf_counter(); import sfcsampler; "
            "sfcsampler.sample(count=1000); print(time.perf_counter() - t)")
    env = dict(os.environ, PYTHONPATH=os.path.join(BUILD, "python"))
    times = [float(run([sys.executable, "-c", code], env=env)) for _ in range(ROUNDS)]
    return [("9. new interpreter: import sfcsampler + first 1 000 in-process samples",
             f"median {statistics.median(times) * 1e3:.0f} ms "
             f"({min(times) * 1e3:.0f}-{max(times) * 1e3:.0f})", "", "target 150 ms")]


def core_benchmarks(pattern):
    """{(name, label): items per second} of core_benchmark's runs matching `pattern`, on
    core 0 (a threads benchmark gets both cores)."""
    import json
    threads = "Threads" in pattern
    cmd = ([] if threads else ["taskset", "-c", "0"]) + [
        f"{BUILD}/bench/core_benchmark", f"--benchmark_filter={pattern}",
        "--benchmark_format=json", "--benchmark_repetitions=3",
        "--benchmark_report_aggregates_only=true"]
    out = {}
    for b in json.loads(run(cmd))["benchmarks"]:
        if b.get("aggregate_name") == "median":
            out[(b["run_name"], b.get("label", ""))] = b["items_per_second"]
    return out


def row_surfaces():
    """Samples a second from a built tree, one core, per surface; and each surface's rate
    at N = 2^23 + 1 against its rate at 10^6."""
    rates = core_benchmarks("BM_SampleSurface")
    by_label = {}
    for (name, label), rate in rates.items():
        by_label.setdefault(label, {})[int(name.rsplit("/", 1)[1])] = rate
    sphere = by_label.get("sphere", {}).get(1_000_000)
    rows = []
    for label, at in by_label.items():
        small, large = at.get(1_000_000), at.get((1 << 23) + 1)
        if small is None or large is None:
            continue
        rows.append((f"10. per-sample cost from a built tree, one core: {label}",
                     f"{small / 1e6:.1f} M/s at 10^6",
                     f"sphere/this {sphere / small:.2f}x" if sphere else "",
                     f"2^23+1 costs {small / large:.2f}x of 10^6 a sample (target: sphere "
                     "50 M/s, every surface within 2x of it, 2^23+1 within 1.2x)"))
    return rows


def row_threads():
    """Two threads against one, the same samples (wall time)."""
    rates = core_benchmarks("BM_SampleFromBuiltTreeThreads")
    by_threads = {int(name.rsplit("/", 2)[1]): rate for (name, _), rate in rates.items()}
    one, two = by_threads.get(1), by_threads.get(2)
    if not one or not two:
        return []
    return [("11. two threads against one from a built tree (C++, wall)",
             f"{two / 1e6:.1f} M/s on 2", f"{one / 1e6:.1f} M/s on 1",
             f"{two / one:.2f}x (target 1.8x)")]


def row_core():
    out = run(["taskset", "-c", "0", f"{BUILD}/bench/core_benchmark",
               "--benchmark_filter="
               "BuildTreeAndSampleSphere/1000000/1$|BuildTreeOnly|SampleFromBuiltTree/0/0",
               "--benchmark_repetitions=3", "--benchmark_report_aggregates_only=true"])
    median = {}
    for line in out.splitlines():
        if "_median" in line:
            parts = line.split()
            median[parts[0]] = f"{parts[1]} {parts[2]}"
    build_and_sample = next((v for k, v in median.items() if "BuildTreeAndSample" in k), "?")
    build = next((v for k, v in median.items() if "BuildTreeOnly" in k), "?")
    sample = next((v for k, v in median.items() if "SampleFromBuiltTree" in k), "?")
    return [("2. tree build + 10^6 sphere samples, one core", build_and_sample,
             f"of it: build {build}, 10^6 samples from a built tree {sample}", "target 60 ms")]


NUMPY_PLY = """
import sys, numpy as np
n = int(sys.argv[1]); rng = np.random.default_rng(1)
u = rng.random(n); v = rng.random(n); z = 1 - 2 * u; r = np.sqrt(1 - z * z); phi = 2 * np.pi * v
a = np.empty(n, dtype=[(c, '<f8') for c in ('x', 'y', 'z')])
a['x'] = r * np.cos(phi); a['y'] = r * np.sin(phi); a['z'] = z
with open(sys.argv[2], 'wb') as f:
    f.write(f"ply\\nformat binary_little_endian 1.0\\nelement vertex {n}\\nproperty double x\\n"
            f"property double y\\nproperty double z\\nend_header\\n".encode())
    f.write(a.tobytes())
"""


def same_file(a, b):
    """Fails unless the two PLY files declare the same properties and have
    the same body size: the row compares writing the same file."""
    def layout(path):
        with open(path, "rb") as f:
            head = f.read(4096)
        end = head.index(b"end_header\n") + len(b"end_header\n")
        lines = [l for l in head[:end].split(b"\n") if not l.startswith(b"comment")]
        return lines, os.path.getsize(path) - end
    if layout(a) != layout(b):
        raise SystemExit(f"row 3 compares different files: {layout(a)} against {layout(b)}")


def row_cold_cli(n=4_000_000):
    with tempfile.TemporaryDirectory() as tmp:
        script = os.path.join(tmp, "numpy_ply.py")
        with open(script, "w") as f:
            f.write(NUMPY_PLY)
        ours, theirs = paired(
            lambda: run([f"{BUILD}/client/sfcsampler", "sample", "-n", str(n), "-q", "--format",
                         "ply", "--columns", "x,y,z", "-o", os.path.join(tmp, "a.ply")]),
            lambda: run([sys.executable, script, str(n), os.path.join(tmp, "b.ply")]))
        same_file(os.path.join(tmp, "a.ply"), os.path.join(tmp, "b.ply"))
    return [(f"3. cold CLI, {n / 1e6:.0f} M sphere samples to a binary PLY file, 5 paired runs",
             f"median {statistics.median(ours):.2f} s ({min(ours):.2f}-{max(ours):.2f})",
             f"numpy script {min(theirs):.2f}-{max(theirs):.2f} s",
             "target: our median <= the script's fastest: " +
             ("met" if statistics.median(ours) <= min(theirs) else "not met"))]


def table_of(cmd, title):
    try:
        out = run(cmd)
    except (subprocess.CalledProcessError, FileNotFoundError) as e:
        return f"\n{title}: failed ({e})\n"
    table = "\n".join(line for line in out.splitlines() if line.startswith("|"))  # no log lines
    return f"\n{title}\n{table}"


def main():
    sys.path.insert(0, os.path.join(BUILD, "python"))
    import sfcsampler
    from sfcsampler import _core
    path = getattr(_core, "VECTOR_PATH", None)
    print(f"# Throughput, algorithm {sfcsampler.ALGORITHM_VERSION}"
          + (f", vector path {path}" if path else "") + f", {os.cpu_count()} CPUs\n")
    print("| measure | ours | peer | ratio / target |\n|---|---|---|---|")
    for rows in (row_python(), row_core(), row_cold_cli(), row_warm_kernel(), row_first_sample(),
                 row_surfaces(), row_threads()):
        for r in rows:
            print("| " + " | ".join(r) + " |")
    sys.stdout.flush()
    if QUICK:
        return
    print(table_of([f"{BUILD}/bench/stream_benchmark", "4000000"],
                   "## 4, 5. Streams over loopback and cache hits (bench/stream_benchmark)"))
    print(table_of(["taskset", "-c", "0", f"{BUILD}/bench/model_benchmark", "1000000", "3"],
                   "## 6. Models against the built-in sphere (bench/model_benchmark)"))
    print(table_of(["/usr/bin/python3", os.path.join(HERE, "mesh_vs_open3d.py"), BUILD, "1000000"],
                   "## 7. Mesh against Open3D (bench/mesh_vs_open3d.py)"))
    print(table_of(["/usr/bin/python3", os.path.join(HERE, "many_meshes.py"), "--no-dask"],
                   "## 12. sample_many of 1 000 small meshes against Open3D's loop "
                   "(bench/many_meshes.py; target 3x)"))


if __name__ == "__main__":
    main()
