#!/usr/bin/env python3
"""How fast the embedded Python path fills 10^6 samples from a built tree,
next to the C++ benchmark doing the same (bench/core_benchmark.cc,
BM_SampleFromBuiltTree: unit sphere, uniform density, Hilbert, jittered,
one thread). Prints a table; run on a quiet machine:

  PYTHONPATH=build/python taskset -c 0 python3 bench/python_fill.py [build/bench/core_benchmark]
"""

import json
import statistics
import subprocess
import sys
import time

import sfcsampler

N = 1_000_000
REPEATS = 15


def python_fill(threads):
    sampler = sfcsampler.Sampler(max_trees=1, threads=threads)
    sampler.sample(surface="sphere", count=N)  # builds and keeps the tree
    times = []
    for _ in range(REPEATS):
        start = time.perf_counter()
        s = sampler.sample(surface="sphere", count=N)
        times.append(time.perf_counter() - start)
        assert len(s) == N and s.tree["cache_hit"]
    return min(times), statistics.median(times)


def cpp_fill(binary):
    out = subprocess.run([binary, "--benchmark_filter=BM_SampleFromBuiltTree/0/0",
                          f"--benchmark_repetitions={REPEATS}", "--benchmark_format=json"],
                         capture_output=True, text=True, check=True).stdout
    runs = [b["real_time"] / 1e3 for b in json.loads(out)["benchmarks"] if b.get("run_type") == "iteration"]
    return min(runs), statistics.median(runs)


def main():
    binary = sys.argv[1] if len(sys.argv) > 1 else "build/bench/core_benchmark"
    cpp = cpp_fill(binary)
    py1 = python_fill(1)
    print(f"10^6 samples, unit sphere, uniform, Hilbert, jittered, tree already built; {REPEATS} runs")
    print(f"{'path':<42} {'min ms':>8} {'median ms':>10} {'M samples/s':>12} {'vs C++':>7}")
    rows = [("C++ SampleCursor (core_benchmark)", cpp), ("Python Sampler.sample(), threads=1", py1)]
    for name, (best, median) in rows:
        print(f"{name:<42} {best * 1e3:>8.1f} {median * 1e3:>10.1f} {N / median / 1e6:>12.2f}"
              f" {cpp[1] / median:>7.2f}")
    py4 = python_fill(0)
    print(f"{'Python Sampler.sample(), threads=0 (<=4)':<42} {py4[0] * 1e3:>8.1f} {py4[1] * 1e3:>10.1f}"
          f" {N / py4[1] / 1e6:>12.2f} {cpp[1] / py4[1]:>7.2f}")


if __name__ == "__main__":
    main()
