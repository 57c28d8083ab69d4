#!/usr/bin/env python3
"""How fast the embedded Python path fills 10^6 samples from a built tree,
next to the C++ benchmark doing the same (bench/core_benchmark.cc,
BM_SampleFromBuiltTree: unit sphere, uniform density, Hilbert, jittered,
one thread). The two are run in alternating rounds, so that a shared
machine's changing load hits both alike; each round's ratio compares the
best of 3 runs on each side. Prints a table:

  PYTHONPATH=build/python taskset -c 0 python3 bench/python_fill.py [build/bench/core_benchmark]

With --server HOST:PORT it also times Client.sample() of 10^6 torus samples
from that server: the first request (the server builds the tree) and
repeats (cache hits), in float64 and float32.
"""

import argparse
import json
import statistics
import subprocess
import time

import sfcsampler

N = 1_000_000
ROUNDS = 7
PER_ROUND = 3


def python_best(sampler):
    times = []
    for _ in range(PER_ROUND):
        start = time.perf_counter()
        s = sampler.sample(surface="sphere", count=N)
        times.append(time.perf_counter() - start)
        assert len(s) == N and s.tree["cache_hit"]
    return min(times)


def cpp_best(binary):
    out = subprocess.run([binary, "--benchmark_filter=BM_SampleFromBuiltTree/0/0",
                          f"--benchmark_repetitions={PER_ROUND}", "--benchmark_format=json"],
                         capture_output=True, text=True, check=True).stdout
    return min(b["real_time"] / 1e3 for b in json.loads(out)["benchmarks"]
               if b.get("run_type") == "iteration")


def wire(server):
    with sfcsampler.Client(server) as client:
        start = time.perf_counter()
        client.sample(surface="torus", count=N, seed=12345)
        first = time.perf_counter() - start
        print(f"\nClient.sample(), 10^6 torus samples from {server}")
        print(f"{'request':<34} {'min s':>7} {'median s':>9}")
        print(f"{'first (the server builds the tree)':<34} {first:>7.2f} {first:>9.2f}")
        for precision in ("float64", "float32"):
            times = []
            for _ in range(5):
                start = time.perf_counter()
                client.sample(surface="torus", count=N, precision=precision)
                times.append(time.perf_counter() - start)
            print(f"{'cache hit, ' + precision:<34} {min(times):>7.2f} "
                  f"{statistics.median(times):>9.2f}")


def main():
    parser = argparse.ArgumentParser(description="embedded fill speed against the C++ benchmark")
    parser.add_argument("core_benchmark", nargs="?", default="build/bench/core_benchmark")
    parser.add_argument("--server", help="HOST:PORT of a server to time Client.sample() against")
    args = parser.parse_args()

    one = sfcsampler.Sampler(max_trees=1, threads=1)
    many = sfcsampler.Sampler(max_trees=1, threads=0)
    one.sample(surface="sphere", count=N)  # build and keep the trees
    many.sample(surface="sphere", count=N)
    rounds = []
    for _ in range(ROUNDS):
        rounds.append((cpp_best(args.core_benchmark), python_best(one), python_best(many)))
    print(f"10^6 samples, unit sphere, uniform, Hilbert, jittered, tree already built;"
          f" {ROUNDS} alternating rounds, best of {PER_ROUND} runs per round")
    print(f"{'path':<42} {'best ms':>8} {'median ms':>10} {'M samples/s':>12} {'C++ / this':>11}")
    names = ("C++ SampleCursor (core_benchmark)", "Python Sampler.sample(), threads=1",
             "Python Sampler.sample(), threads=0 (<=4)")
    for i, name in enumerate(names):
        times = [r[i] for r in rounds]
        ratio = statistics.median(r[0] / r[i] for r in rounds)
        print(f"{name:<42} {min(times) * 1e3:>8.1f} {statistics.median(times) * 1e3:>10.1f}"
              f" {N / statistics.median(times) / 1e6:>12.2f} {ratio:>11.2f}")
    print("(C++ / this: the median over rounds of the C++ time over this path's time; >= 1 is as "
          "fast)")
    if args.server:
        wire(args.server)


if __name__ == "__main__":
    main()
