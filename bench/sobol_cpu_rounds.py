#!/usr/bin/python3
"""Sobol's CPU against jittered's (issue 36's "within 2x"), alternating rounds in one run.

For each surface and vector path (the default, then `SFCSAMPLER_VECTOR_PATH=avx2`, what an AVX2
machine runs), the in-process CLI writes 10^6 samples as NPY to /dev/null, sobol then jittered,
--rounds times; CPU is user + sys of each child process. Prints medians and ranges.

Usage: /usr/bin/python3 bench/sobol_cpu_rounds.py [--cli build/client/sfcsampler] [--rounds 7]
           [SURFACE ...]   (default: sphere obj:/tmp/ico.obj ply:/tmp/ico6.ply
                            step:/tmp/fx/box_with_hole.step; make them as docs/MEASURED.md says)
"""
import argparse
import os
import resource
import statistics
import subprocess
import sys


def cpu_seconds(cli, args, env):
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run([cli, "sample", "-q", "--count", "1000000", "--format", "npy", "-o",
                    "/dev/null"] + args, check=True, env=env)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--cli", default=os.path.join(os.path.dirname(__file__), "..", "build",
                                                  "client", "sfcsampler"))
    ap.add_argument("--rounds", type=int, default=7)
    ap.add_argument("surfaces", nargs="*", default=["sphere", "obj:/tmp/ico.obj",
                                                    "ply:/tmp/ico6.ply",
                                                    "step:/tmp/fx/box_with_hole.step"])
    args = ap.parse_args()
    print("| surface | path | sobol CPU, median (range) | jittered CPU | sobol / jittered |")
    print("|---|---|---:|---:|---:|")
    for surface in args.surfaces:
        for path in ("default", "avx2"):
            env = dict(os.environ)
            if path != "default":
                env["SFCSAMPLER_VECTOR_PATH"] = path
            times = {"sobol": [], "jittered": []}
            for _ in range(args.rounds):
                for sequence in times:
                    times[sequence].append(cpu_seconds(
                        args.cli, ["--surface", surface, "--sequence", sequence], env))
            cell = {k: f"{statistics.median(v) * 1e3:.0f} ms ({min(v) * 1e3:.0f}-"
                       f"{max(v) * 1e3:.0f})" for k, v in times.items()}
            ratio = statistics.median(times["sobol"]) / statistics.median(times["jittered"])
            print(f"| {surface} | {path} | {cell['sobol']} | {cell['jittered']} | {ratio:.2f}x |",
                  flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
